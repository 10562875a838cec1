#include "lidarloop/app/evaluation_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "lidarloop/io/plot.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::app {
namespace {

constexpr std::uint8_t kBlack = 0;
constexpr std::uint8_t kNotEvaluated = 210;  // pairs inside the minimum gap: light grey
constexpr std::uint8_t kWhite = 255;

std::string FileSafe(const std::string& name) {
    std::string safe;
    for (char c : name) safe += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    return safe;
}

// One pixel per pair, as in Röhling figs. 5-7 and Magnusson figs. 3-4.
template <typename IsBlack>
io::Image PairImage(const eval::GroundTruth& truth, IsBlack is_black) {
    const auto n = static_cast<int>(truth.size());
    io::Image image{std::max(n, 1), std::max(n, 1), 1, {}};
    image.pixels.assign(static_cast<std::size_t>(image.width) * image.height, kWhite);
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const auto a = static_cast<std::size_t>(i);
            const auto b = static_cast<std::size_t>(j);
            std::uint8_t& pixel = image.pixels[a * static_cast<std::size_t>(n) + b];
            if (i == j || !truth.Comparable(std::min(a, b), std::max(a, b))) {
                pixel = kNotEvaluated;
            } else if (is_black(a, b)) {
                pixel = kBlack;
            }
        }
    }
    return image;
}

std::string Figure(double value, int digits = 4) {
    if (!std::isfinite(value)) return value > 0 ? "∞" : "–";
    char text[64];
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    return text;
}

io::Plot RocPlot(const std::vector<MethodEvaluation>& evaluations, bool precision_recall) {
    io::Plot plot;
    plot.title = precision_recall ? "Precision-recall over all scan pairs"
                                  : "ROC over all scan pairs (Roehling fig. 4)";
    plot.x_label = precision_recall ? "recall" : "false positive rate";
    plot.y_label = precision_recall ? "precision" : "true positive rate";
    plot.x_min = plot.y_min = 0.0;
    plot.x_max = plot.y_max = 1.0;
    for (const MethodEvaluation& e : evaluations) {
        io::PlotSeries series{e.name, {}, {}, io::PlotSeries::Style::kLines};
        for (const eval::CurvePoint& p : e.pairwise.curve) {
            if (precision_recall && p.confusion.PredictedPositives() == 0) continue;
            series.x.push_back(precision_recall ? p.tpr : p.fpr);
            series.y.push_back(precision_recall ? p.precision : p.tpr);
        }
        plot.series.push_back(std::move(series));
    }
    if (!precision_recall) {
        plot.series.push_back({"chance", {0.0, 1.0}, {0.0, 1.0}, io::PlotSeries::Style::kLines});
    }
    return plot;
}

// `f` sampled at 401 points over [lo, hi].
template <typename F>
io::PlotSeries SampledCurve(std::string title, double lo, double hi, F f) {
    io::PlotSeries series{std::move(title), {}, {}, io::PlotSeries::Style::kLines};
    for (int k = 0; k <= 400; ++k) {
        const double x = lo + (hi - lo) * k / 400.0;
        series.x.push_back(x);
        series.y.push_back(f(x));
    }
    return series;
}

// `values` (within [lo, hi]) as a density histogram of 40 bins.
io::PlotSeries DensityHistogram(const std::vector<double>& values, double lo, double hi) {
    constexpr int kBins = 40;
    const double width = (hi - lo) / kBins;
    io::PlotSeries histogram{"scans", {}, {}, io::PlotSeries::Style::kBoxes};
    std::vector<double> counts(kBins, 0.0);
    for (double d : values) {
        counts[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>((d - lo) / width)))] +=
            1;
    }
    for (int b = 0; b < kBins; ++b) {
        histogram.x.push_back(lo + (b + 0.5) * width);
        histogram.y.push_back(counts[static_cast<std::size_t>(b)] /
                              (static_cast<double>(values.size()) * width));
    }
    return histogram;
}

io::Plot EmPlot(const MethodEvaluation& e) {
    io::Plot plot;
    plot.title = e.name + ": smallest difference of every scan, EM fit (Magnusson fig. 2)";
    plot.x_label = "distance to the most similar scan outside the gap";
    plot.y_label = "density";
    std::vector<double> finite;
    for (double d : e.smallest_differences) {
        if (std::isfinite(d)) finite.push_back(d);
    }
    if (finite.empty()) return plot;
    const auto [lo_it, hi_it] = std::minmax_element(finite.begin(), finite.end());
    const double lo = *lo_it;
    const double hi = *hi_it > lo ? *hi_it : lo + 1.0;
    plot.series.push_back(DensityHistogram(finite, lo, hi));
    if (!e.em.Fitted()) {
        plot.title += " - not fitted: too few distinct values";
        return plot;
    }
    const eval::MixtureFit& fit = e.em.fit;
    plot.series.push_back(
        SampledCurve("mixture", lo, hi, [&](double x) { return fit.Density(x); }));
    for (std::size_t c = 0; c < fit.components.size(); ++c) {
        plot.series.push_back(
            SampledCurve("component " + std::to_string(c + 1), lo, hi,
                         [&](double x) { return fit.components[c].WeightedDensity(x); }));
    }
    if (e.em.t_d) plot.vertical_lines.push_back(*e.em.t_d);
    return plot;
}

io::Plot CountsPlot(const MethodEvaluation& e) {
    io::Plot plot;
    plot.title = e.name + ": scans by label against t_d (Magnusson fig. 1)";
    plot.x_label = "difference threshold t_d";
    plot.y_label = "share of scans (%)";
    const double scans = static_cast<double>(e.best_matches.size());
    io::PlotSeries tp{"true positives", {}, {}, io::PlotSeries::Style::kSteps};
    io::PlotSeries fp{"false positives", {}, {}, io::PlotSeries::Style::kSteps};
    io::PlotSeries mismatch{"mismatches", {}, {}, io::PlotSeries::Style::kSteps};
    for (const eval::TaxonomyPoint& p : e.per_scan.curve) {
        if (!std::isfinite(p.t_d)) continue;
        for (auto* s : {&tp, &fp, &mismatch}) s->x.push_back(p.t_d);
        tp.y.push_back(100.0 * static_cast<double>(p.counts.true_positive) / scans);
        fp.y.push_back(100.0 * static_cast<double>(p.counts.false_positive) / scans);
        mismatch.y.push_back(100.0 * static_cast<double>(p.counts.mismatch) / scans);
    }
    plot.series = {tp, fp, mismatch};
    if (std::isfinite(e.per_scan.zero_error.t_d)) {
        plot.vertical_lines.push_back(e.per_scan.zero_error.t_d);
    }
    return plot;
}

std::string LearningCriterion(const std::vector<MethodEvaluation>& evaluations) {
    for (const MethodEvaluation& e : evaluations) {
        if (e.learnt) return eval::ToString(e.learnt->criterion);
    }
    return "–";
}

void WritePairwiseTable(std::ostream& out, const std::vector<MethodEvaluation>& evaluations) {
    out << "## All scan pairs (Röhling et al. 2015, tables I and II, fig. 4)\n\n"
        << "| method | pairs (loops) | best MCC (τ) | best F1 (τ) | ROC AUC | learnt τ → test F1 "
           "/ MCC | MCC at the default τ |\n|---|---|---|---|---|---|---|\n";
    for (const MethodEvaluation& e : evaluations) {
        const auto& p = e.pairwise;
        out << "| " << e.name << " | " << p.pairs << " (" << p.positives << ") | "
            << Figure(p.best_mcc.score, 3) << " (" << Figure(p.best_mcc.threshold) << ") | "
            << Figure(p.best_f1.score, 3) << " (" << Figure(p.best_f1.threshold) << ") | "
            << (p.roc_auc ? Figure(*p.roc_auc, 3) : "–") << " | ";
        if (e.learnt) {
            out << Figure(e.learnt->threshold) << " → " << Figure(e.learnt->test_f1, 3) << " / "
                << Figure(e.learnt->test_mcc, 3);
        } else {
            out << "–";
        }
        out << " | "
            << (e.at_default ? Figure(eval::Mcc(*e.at_default), 3) +
                                   " (τ = " + Figure(*e.default_threshold) + ")"
                             : "–")
            << " |\n";
    }
    out << "\nLearnt τ (criterion: best " << LearningCriterion(evaluations) << ") trained on: ";
    for (const MethodEvaluation& e : evaluations) {
        if (e.learnt) out << e.name << " — " << e.learnt_on << "; ";
    }
    out << "tested on all pairs of this sequence not used for training.\n";
}

void WriteFixedThresholdTable(std::ostream& out, const std::vector<MethodEvaluation>& evaluations) {
    if (evaluations.empty() || evaluations.front().fixed_thresholds.empty()) return;
    out << "\nMCC at fixed thresholds (table II):\n\n| method |";
    for (double tau : evaluations.front().fixed_thresholds) out << " L_" << Figure(tau) << " |";
    out << "\n|---|";
    for (std::size_t t = 0; t < evaluations.front().fixed_thresholds.size(); ++t) out << "---|";
    out << "\n";
    for (const MethodEvaluation& e : evaluations) {
        out << "| " << e.name << " |";
        for (const eval::Confusion& c : e.at_fixed) out << " " << Figure(eval::Mcc(c), 3) << " |";
        out << "\n";
    }
}

void WritePerScanTable(std::ostream& out, const std::vector<MethodEvaluation>& evaluations) {
    out << "\n## Every scan and its most similar scan (Magnusson et al. 2009, tables I and II, "
           "figs. 1 and 2)\n\n| method | overlapping / other scans | recall at zero errors "
           "(t_d) | EM t_d | median best/second ratio |\n|---|---|---|---|---|\n";
    for (const MethodEvaluation& e : evaluations) {
        const auto& z = e.per_scan.zero_error;
        out << "| " << e.name << " | " << e.per_scan.overlapping << " / "
            << e.per_scan.non_overlapping << " | " << Figure(100.0 * z.recall, 3) << " % ("
            << Figure(z.t_d) << ") | " << (e.em.t_d ? Figure(*e.em.t_d) : "–") << " | "
            << (e.distinctiveness.ratio ? Figure(e.distinctiveness.ratio->median, 3) : "–")
            << " |\n";
    }
    out << "\nZero errors: no false positive and no mismatch (table I). Timings on this "
           "machine: ";
    for (const MethodEvaluation& e : evaluations) {
        out << e.name << " " << Figure(e.describe_ms_per_scan_median, 3) << " ms per scan, "
            << Figure(e.ns_per_comparison, 3) << " ns per comparison; ";
    }
}

std::string Percent(double rate) {
    return std::isnan(rate) ? std::string("–") : Figure(100.0 * rate, 3) + " %";
}

std::string MedianMax(const std::optional<eval::Summary>& s, int digits) {
    if (!s) return "–";
    return Figure(s->median, digits) + " / " + Figure(s->max, digits);
}

void WriteRetrievalRow(std::ostream& out, const std::string& name, const std::string& decision,
                       const eval::LoopRetrievalEvaluation& r) {
    out << "| " << name << " | " << decision << " | " << Percent(r.recall_at_1) << " | "
        << Percent(r.recall_at_k) << " | " << r.true_loops << " / " << r.false_loops << " | "
        << (r.loops_with_pose > 0 ? std::to_string(r.wrong_pose_loops) : std::string("–")) << " | "
        << Percent(r.precision) << " | " << Percent(r.recall) << " | "
        << Percent(r.full_precision.recall) << " | " << MedianMax(r.pose_error.translation_m, 3)
        << " | " << MedianMax(r.pose_error.yaw_deg, 3) << " |\n";
}

void WriteRetrievalTable(std::ostream& out, const std::vector<MethodEvaluation>& evaluations) {
    const auto with =
        std::find_if(evaluations.begin(), evaluations.end(),
                     [](const MethodEvaluation& e) { return e.retrieval.has_value(); });
    if (with == evaluations.end()) return;
    out << "\n\n## Loops as the online detector reports them: the descriptor alone and verified "
           "(k = "
        << with->retrieval->top_k
        << " candidates per scan)\n\n"
           "| method | decided by | recall@1 | recall@k | true / false loops | wrong-pose loops | "
           "precision | recall | recall at 100 % precision | pose error (m), median / max | "
           "yaw error (deg), median / max |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const MethodEvaluation& e : evaluations) {
        if (!e.retrieval) continue;
        WriteRetrievalRow(out, e.name, "descriptor threshold", e.retrieval->descriptor);
        if (e.retrieval->verified)
            WriteRetrievalRow(out, e.name, "verification", *e.retrieval->verified);
    }
    out << "\nRecall is over the " << with->retrieval->descriptor.revisiting
        << " revisiting scans (a true loop among the earlier scans outside the gap). recall@k "
           "is the ceiling of verification: it only decides among the candidates. A scan's loop "
           "is its first accepted candidate; pose errors are of the true loops against the "
           "ground-truth relative pose. A wrong-pose loop is off its true relative pose by more "
           "than 1 m or 2 degrees, true or false by place: the loops that would bend a pose "
           "graph. A false loop at the right pose (the same structure seen from beyond the "
           "distance of the ground truth) is not one.";
}

// The n x n images are drawn from the similarity matrices, which the evaluation keeps only
// within output.similarity_matrix_mib.
bool PairImagesDrawn(const std::vector<MethodEvaluation>& evaluations, std::size_t scans) {
    return std::all_of(evaluations.begin(), evaluations.end(),
                       [&](const MethodEvaluation& e) { return e.matrix.size() == scans; });
}

void WriteMethodFigures(std::ostream& out, const std::vector<MethodEvaluation>& evaluations);

void WriteFigureGallery(std::ostream& out, const std::vector<MethodEvaluation>& evaluations,
                        std::size_t scans) {
    if (!PairImagesDrawn(evaluations, scans)) {
        out << "\n\n## Curves\n\n![ROC](roc.png) ![precision-recall](pr.png)\n\n";
        WriteMethodFigures(out, evaluations);
        return;
    }
    out << "\n\n## Similarity matrices (black: pairs under the best-MCC threshold; grey: inside "
           "the minimum gap, not evaluated)\n\n| ground truth |";
    for (const MethodEvaluation& e : evaluations) out << " " << e.name << " |";
    out << "\n|---|";
    for (std::size_t i = 0; i < evaluations.size(); ++i) out << "---|";
    out << "\n| ![](ground_truth.png) |";
    for (const MethodEvaluation& e : evaluations) {
        out << " ![](similarity_" << FileSafe(e.name) << ".png) |";
    }
    out << "\n\n## Curves\n\n![ROC](roc.png) ![precision-recall](pr.png)\n\n";
    WriteMethodFigures(out, evaluations);
}

void WriteMethodFigures(std::ostream& out, const std::vector<MethodEvaluation>& evaluations) {
    for (const MethodEvaluation& e : evaluations) {
        out << "![EM " << e.name << "](em_" << FileSafe(e.name) << ".png) ![counts " << e.name
            << "](counts_" << FileSafe(e.name) << ".png)\n\n";
    }
}

void WritePairImages(const std::filesystem::path& folder, const eval::GroundTruth& truth,
                     const std::vector<MethodEvaluation>& evaluations) {
    io::WritePng(folder / "ground_truth.png", PairImage(truth, [&](std::size_t i, std::size_t j) {
                     return truth.IsLoop(std::min(i, j), std::max(i, j));
                 }));
    for (const MethodEvaluation& e : evaluations) {
        const double tau = e.pairwise.best_mcc.threshold;
        io::WritePng(folder / ("similarity_" + FileSafe(e.name) + ".png"),
                     PairImage(truth, [&](std::size_t i, std::size_t j) {
                         return e.matrix.at(i, j) <= tau;
                     }));
    }
}

}  // namespace

void WriteCurveCsvs(const std::filesystem::path& folder,
                    const std::vector<MethodEvaluation>& evaluations) {
    std::ofstream roc(folder / "roc.csv");
    std::ofstream pr(folder / "pr.csv");
    roc << "method,threshold,fpr,tpr\n";
    pr << "method,threshold,recall,precision\n";
    roc.precision(9);
    pr.precision(9);
    for (const MethodEvaluation& e : evaluations) {
        for (const eval::CurvePoint& p : e.pairwise.curve) {
            roc << e.name << ',' << p.threshold << ',' << p.fpr << ',' << p.tpr << '\n';
            if (p.confusion.PredictedPositives() > 0) {
                pr << e.name << ',' << p.threshold << ',' << p.tpr << ',' << p.precision << '\n';
            }
        }
    }
    roc.close();  // flushes: a full disk fails here, not silently in the destructor
    pr.close();
    if (!roc) throw io::WriteError(folder / "roc.csv", "writing failed");
    if (!pr) throw io::WriteError(folder / "pr.csv", "writing failed");
}

std::vector<std::string> WriteFigures(const std::filesystem::path& folder,
                                      const eval::GroundTruth& truth,
                                      const std::vector<MethodEvaluation>& evaluations) {
    std::vector<std::string> notes;
    if (PairImagesDrawn(evaluations, truth.size())) {
        WritePairImages(folder, truth, evaluations);
    } else {
        notes.push_back(
            "the " + std::to_string(truth.size()) + " x " + std::to_string(truth.size()) +
            " images ground_truth.png and similarity_*.png are drawn only when the similarity "
            "matrix fits output.similarity_matrix_mib; the evaluation streamed the pairs instead");
    }
    if (!io::GnuplotAvailable()) {
        notes.push_back(
            "gnuplot is not installed, so the curves are only in roc.csv and pr.csv "
            "(apt-get install gnuplot-nox)");
        return notes;
    }
    io::RenderPlot(folder / "roc.png", RocPlot(evaluations, false));
    io::RenderPlot(folder / "pr.png", RocPlot(evaluations, true));
    for (const MethodEvaluation& e : evaluations) {
        io::RenderPlot(folder / ("em_" + FileSafe(e.name) + ".png"), EmPlot(e));
        io::RenderPlot(folder / ("counts_" + FileSafe(e.name) + ".png"), CountsPlot(e));
    }
    return notes;
}

void WriteReport(const std::filesystem::path& folder, const ReportContext& context,
                 const std::vector<MethodEvaluation>& evaluations,
                 const std::vector<std::string>& notes) {
    std::ofstream out(folder / "report.md");
    out << "# Loop detection on " << context.dataset << "\n\n"
        << context.scans << " scans. Ground truth: " << context.ground_truth_rule << "\n\n";
    WritePairwiseTable(out, evaluations);
    WriteFixedThresholdTable(out, evaluations);
    WritePerScanTable(out, evaluations);
    WriteRetrievalTable(out, evaluations);
    WriteFigureGallery(out, evaluations, context.scans);
    for (const std::string& note : notes) out << "Note: " << note << "\n\n";
    out.close();
    if (!out) throw io::WriteError(folder / "report.md", "writing failed");
}

}  // namespace lidarloop::app
