// Ground truth and every evaluation metric (lidarloop::eval): the pair-wise protocol (Röhling
// IV-B/C), the per-scan taxonomy and EM threshold (Magnusson II-E), loop retrieval, and the
// trajectory metrics ATE and RPE.
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/eval/em.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/loop_retrieval.hpp"
#include "lidarloop/eval/metrics.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/eval/per_scan.hpp"
#include "lidarloop/eval/summary.hpp"
#include "lidarloop/eval/threshold_learning.hpp"
#include "lidarloop/eval/trajectory.hpp"
#include "part2_helpers.hpp"

namespace lidarloop::python {
namespace {

using namespace eval;

// kNoScan as -1, so that arrays of scan indices stay signed integers.
long long ScanOrMinusOne(std::size_t scan) {
    return scan == kNoScan ? -1 : static_cast<long long>(scan);
}

// The condensed upper triangle (i < j, row-major; SimilarityMatrix::condensed's layout) of
// `distances`: a 1-D condensed array as it is, or the upper triangle of an (n, n) matrix.
std::vector<float> CondensedFrom(const py::handle& distances) {
    CheckFloatArray(distances, "distances");
    const auto array = py::array_t<double, py::array::forcecast>::ensure(distances);
    std::vector<float> condensed;
    if (array.ndim() == 1) {
        for (py::ssize_t k = 0; k < array.shape(0); ++k)
            condensed.push_back(static_cast<float>(array.at(k)));
        return condensed;
    }
    if (array.ndim() != 2 || array.shape(0) != array.shape(1)) {
        throw ShapeError("distances must be a condensed (n(n-1)/2,) array or an (n, n) matrix");
    }
    const auto view = array.unchecked<2>();
    for (py::ssize_t i = 0; i < view.shape(0); ++i) {
        for (py::ssize_t j = i + 1; j < view.shape(0); ++j)
            condensed.push_back(static_cast<float>(view(i, j)));
    }
    return condensed;
}

void BindConfusion(py::module_& m) {
    py::class_<Confusion>(m, "Confusion", "A binary confusion matrix (counts of pairs or scans)")
        .def(py::init([](std::uint64_t tp, std::uint64_t fp, std::uint64_t tn, std::uint64_t fn) {
                 return Confusion{tp, fp, tn, fn};
             }),
             py::arg("tp") = 0, py::arg("fp") = 0, py::arg("tn") = 0, py::arg("fn") = 0)
        .def_readonly("tp", &Confusion::tp)
        .def_readonly("fp", &Confusion::fp)
        .def_readonly("tn", &Confusion::tn)
        .def_readonly("fn", &Confusion::fn)
        .def_property_readonly("precision", &Precision, "TP / (TP + FP); 0 when nothing detected")
        .def_property_readonly("recall", &Recall, "TP / (TP + FN); 0 without loops")
        .def_property_readonly("false_positive_rate", &FalsePositiveRate)
        .def_property_readonly("f1", &F1, "Röhling eq. (9)")
        .def_property_readonly("mcc", &Mcc, "Röhling eq. (10), Matthews correlation")
        .def("__eq__", [](const Confusion& a, const Confusion& b) { return a == b; })
        .def("__repr__", [](const Confusion& c) {
            return "<Confusion tp=" + std::to_string(c.tp) + " fp=" + std::to_string(c.fp) +
                   " tn=" + std::to_string(c.tn) + " fn=" + std::to_string(c.fn) + ">";
        });
}

void BindGroundTruthConfig(py::module_& m) {
    py::class_<GroundTruthConfig>(
        m, "GroundTruthConfig",
        "When two scans show the same place: positions closer than distance_m (strictly), "
        "headings closer than max_heading_deg (0: any), scans more than min_gap apart and more "
        "than min_path_m of path apart (0: any).")
        .def(py::init(&FromKeywords<GroundTruthConfig>),
             "Keyword arguments override the defaults (distance_m=10, max_heading_deg=0, "
             "min_gap=0, min_gap_unit='scans', min_path_m=0)")
        .def_readwrite("distance_m", &GroundTruthConfig::distance_m)
        .def_readwrite("max_heading_deg", &GroundTruthConfig::max_heading_deg)
        .def_readwrite("min_path_m", &GroundTruthConfig::min_path_m,
                       "pairs not more than this much path apart (metres on the poses) are not "
                       "evaluated; 0: no path rule")
        .def_property(
            "min_gap", [](const GroundTruthConfig& c) { return c.min_gap.value; },
            [](GroundTruthConfig& c, double value) { c.min_gap.value = value; },
            "S: pairs not more than this apart (in min_gap_unit) are not evaluated")
        .def_property(
            "min_gap_unit",
            [](const GroundTruthConfig& c) { return core::ToString(c.min_gap.unit); },
            [](GroundTruthConfig& c, const std::string& unit) {
                c.min_gap.unit = core::ParseMinGapUnit(unit);
            },
            "'scans', 'seconds' or 'metres' (of path on the poses)")
        .def("describe", &GroundTruthConfig::Describe);
}

void BindGroundTruth(py::module_& m) {
    py::class_<GroundTruth>(m, "GroundTruth", "The positive pairs of a sequence under one rule")
        .def_readonly("config", &GroundTruth::config)
        .def("__len__", &GroundTruth::size)
        .def_property_readonly(
            "loops",
            [](const GroundTruth& t) {
                py::array_t<long long> pairs(
                    {static_cast<py::ssize_t>(t.loop_count), py::ssize_t{2}});
                auto out = pairs.mutable_unchecked<2>();
                py::ssize_t k = 0;
                t.ForEachLoop([&](const LoopPair& loop) {
                    out(k, 0) = static_cast<long long>(loop.i);
                    out(k, 1) = static_cast<long long>(loop.j);
                    ++k;
                });
                return pairs;
            },
            "(P, 2) int64: every positive pair i < j, sorted (computed on each access)")
        .def_property_readonly(
            "loop_distances_m",
            [](const GroundTruth& t) {
                std::vector<double> d;
                d.reserve(t.loop_count);
                t.ForEachLoop([&](const LoopPair& loop) { d.push_back(loop.distance_m); });
                return ArrayOf(d);
            },
            "(P,) distance between the sensor positions of each positive pair, metres (computed "
            "on each access)")
        .def_property_readonly(
            "nearest",
            [](const GroundTruth& t) {
                std::vector<long long> nearest;
                for (std::size_t s : t.nearest) nearest.push_back(ScanOrMinusOne(s));
                return ArrayOf(nearest);
            },
            "(N,) per scan the nearest scan outside the gap passing the heading rule, -1: none")
        .def_property_readonly("nearest_distance_m",
                               [](const GroundTruth& t) { return ArrayOf(t.nearest_distance_m); })
        .def(
            "is_loop",
            [](const GroundTruth& t, std::size_t i, std::size_t j) {
                return t.IsLoop(CheckedScan(t, i), CheckedScan(t, j));
            },
            py::arg("i"), py::arg("j"))
        .def(
            "comparable",
            [](const GroundTruth& t, std::size_t i, std::size_t j) {
                return t.Comparable(CheckedScan(t, i), CheckedScan(t, j));
            },
            py::arg("i"), py::arg("j"))
        .def(
            "overlapping",
            [](const GroundTruth& t, std::size_t scan) {
                return t.Overlapping(CheckedScan(t, scan));
            },
            py::arg("scan"))
        .def_property_readonly("overlapping_count", &GroundTruth::OverlappingCount)
        .def_property_readonly("comparable_pair_count", &GroundTruth::ComparablePairCount)
        .def("describe", &GroundTruth::Describe);
    m.def(
        "build_ground_truth",
        [](const py::handle& times_s, const py::handle& T_world_sensor,
           std::optional<GroundTruthConfig> config,
           const std::optional<std::vector<double>>& path_m, const py::kwargs& rule) {
            if (config && !rule.empty())
                throw core::ConfigError("give either config or keyword arguments, not both");
            const GroundTruthConfig gt_config =
                config ? *config : FromKeywords<GroundTruthConfig>(rule);
            std::vector<core::StampedPose> poses = PosesFromArrays(times_s, T_world_sensor);
            if (path_m) SetPathM(*path_m, poses);
            py::gil_scoped_release release;
            return BuildGroundTruth(poses, gt_config);
        },
        py::arg("times_s"), py::arg("T_world_sensor"), py::arg("config") = py::none(),
        py::arg("path_m") = py::none(),
        "Ground truth from poses (times_s (N,), T_world_sensor (N, 4, 4)); the rule as a "
        "GroundTruthConfig or its fields as keywords (distance_m=..., max_heading_deg=..., "
        "min_gap=..., min_gap_unit=...). path_m: per scan, the path travelled (Dataset.path_m: "
        "the drive's for some frames of a KITTI sequence); None: the straight steps.");
    m.def(
        "heading_difference_deg",
        [](const py::handle& a, const py::handle& b) {
            return HeadingDifferenceDeg(TransformFromArray(a, "T_world_a"),
                                        TransformFromArray(b, "T_world_b"));
        },
        py::arg("T_world_a"), py::arg("T_world_b"),
        "Angle between two sensors' forward axes on the ground plane (world z up), degrees");
}

// Scored pairs are 16-byte structs; Python sees them through column arrays.
struct ScoredPairs {
    std::vector<ScoredPair> pairs;
};

ScoredPairs PairsFromColumns(const py::handle& i, const py::handle& j, const py::handle& distance,
                             const py::handle& loop) {
    const auto is = py::array_t<long long, py::array::forcecast>::ensure(i);
    const auto js = py::array_t<long long, py::array::forcecast>::ensure(j);
    const auto ds = py::array_t<double, py::array::forcecast>::ensure(distance);
    const auto ls = py::array_t<bool, py::array::forcecast>::ensure(loop);
    if (!is || !js || !ds || !ls || is.ndim() != 1 || js.size() != is.size() ||
        ds.size() != is.size() || ls.size() != is.size()) {
        throw ShapeError("i, j, distance and loop must be 1-D arrays of one length");
    }
    ScoredPairs out;
    for (py::ssize_t k = 0; k < is.size(); ++k) {
        constexpr long long kMaxScan = std::numeric_limits<std::uint32_t>::max();
        if (is.at(k) < 0 || js.at(k) < 0 || is.at(k) > kMaxScan || js.at(k) > kMaxScan)
            throw ShapeError("scan indices must be in [0, 2^32 - 1]: pairs hold 32-bit scans");
        out.pairs.push_back({static_cast<std::uint32_t>(is.at(k)),
                             static_cast<std::uint32_t>(js.at(k)), static_cast<float>(ds.at(k)),
                             ls.at(k)});
    }
    return out;
}

void BindScoredPairs(py::module_& m) {
    py::class_<ScoredPairs>(m, "ScoredPairs",
                            "Evaluated scan pairs i < j: descriptor distance (+inf: never scored) "
                            "and whether the ground truth calls them one place")
        .def(py::init(&PairsFromColumns), py::arg("i"), py::arg("j"), py::arg("distance"),
             py::arg("loop"))
        .def("__len__", [](const ScoredPairs& p) { return p.pairs.size(); })
        .def_property_readonly("i",
                               [](const ScoredPairs& p) {
                                   std::vector<long long> v;
                                   for (const auto& s : p.pairs) v.push_back(s.i);
                                   return ArrayOf(v);
                               })
        .def_property_readonly("j",
                               [](const ScoredPairs& p) {
                                   std::vector<long long> v;
                                   for (const auto& s : p.pairs) v.push_back(s.j);
                                   return ArrayOf(v);
                               })
        .def_property_readonly("distance",
                               [](const ScoredPairs& p) {
                                   std::vector<float> v;
                                   for (const auto& s : p.pairs) v.push_back(s.distance);
                                   return ArrayOf(v);
                               })
        .def_property_readonly("loop", [](const ScoredPairs& p) {
            std::vector<bool> v;
            for (const auto& s : p.pairs) v.push_back(s.loop);
            py::array_t<bool> array(static_cast<py::ssize_t>(v.size()));
            for (std::size_t k = 0; k < v.size(); ++k) array.mutable_at(k) = v[k];
            return array;
        });
    m.def(
        "collect_pairs",
        [](const py::handle& distances, const GroundTruth& truth) {
            const std::vector<float> condensed = CondensedFrom(distances);
            py::gil_scoped_release release;
            return ScoredPairs{CollectPairs(condensed, truth)};
        },
        py::arg("distances"), py::arg("truth"),
        "The pairs to evaluate: every comparable pair i < j of a distance matrix ((n, n), or "
        "condensed (n(n-1)/2,) upper triangle), labelled by the ground truth.");
}

void BindPairwise(py::module_& m) {
    py::class_<BestThreshold>(m, "BestThreshold")
        .def_readonly("threshold", &BestThreshold::threshold, "tau: distance <= tau is a loop")
        .def_readonly("score", &BestThreshold::score, "MCC or F1 at tau")
        .def_readonly("confusion", &BestThreshold::confusion);
    py::class_<PairwiseEvaluation>(m, "PairwiseEvaluation",
                                   "The threshold sweep over all pairs (Röhling IV-B/C, fig. 4)")
        .def_readonly("pairs", &PairwiseEvaluation::pairs)
        .def_readonly("positives", &PairwiseEvaluation::positives)
        .def_readonly("negatives", &PairwiseEvaluation::negatives)
        .def_readonly("distinct_thresholds", &PairwiseEvaluation::distinct_thresholds)
        .def_property_readonly(
            "curve",
            [](const PairwiseEvaluation& e) {
                std::vector<double> threshold, tpr, fpr, precision;
                std::vector<long long> tp, fp, tn, fn;
                for (const CurvePoint& p : e.curve) {
                    threshold.push_back(p.threshold);
                    tpr.push_back(p.tpr);
                    fpr.push_back(p.fpr);
                    precision.push_back(p.precision);
                    tp.push_back(static_cast<long long>(p.confusion.tp));
                    fp.push_back(static_cast<long long>(p.confusion.fp));
                    tn.push_back(static_cast<long long>(p.confusion.tn));
                    fn.push_back(static_cast<long long>(p.confusion.fn));
                }
                py::dict curve;
                curve["threshold"] = ArrayOf(threshold);
                curve["tpr"] = ArrayOf(tpr);
                curve["fpr"] = ArrayOf(fpr);
                curve["precision"] = ArrayOf(precision);
                curve["tp"] = ArrayOf(tp);
                curve["fp"] = ArrayOf(fp);
                curve["tn"] = ArrayOf(tn);
                curve["fn"] = ArrayOf(fn);
                return curve;
            },
            "ROC and PR curve as arrays, threshold ascending from -inf: threshold, tpr, fpr, "
            "precision, tp, fp, tn, fn")
        .def_readonly("roc_auc", &PairwiseEvaluation::roc_auc, "None without both classes")
        .def_readonly("best_mcc", &PairwiseEvaluation::best_mcc)
        .def_readonly("best_f1", &PairwiseEvaluation::best_f1);
    m.def(
        "evaluate_pairs",
        [](const ScoredPairs& pairs, std::size_t max_curve_points) {
            PairwiseConfig config;
            config.max_curve_points = max_curve_points;
            config.Validate();
            py::gil_scoped_release release;
            return EvaluatePairs(pairs.pairs, config);
        },
        py::arg("pairs"), py::arg("max_curve_points") = PairwiseConfig{}.max_curve_points,
        "Sweeps the threshold over every distinct finite distance: ROC/PR curve, AUC, best "
        "MCC and F1 (max_curve_points: 0 keeps every point).");
    m.def(
        "confusion_at",
        [](const ScoredPairs& pairs, double threshold) {
            return ConfusionAt(pairs.pairs, threshold);
        },
        py::arg("pairs"), py::arg("threshold"), "L_tau: distance <= threshold is a loop");
    m.def(
        "confusions_at",
        [](const ScoredPairs& pairs, const py::handle& thresholds) {
            const std::vector<double> values = DoublesFrom(thresholds, "thresholds");
            return ConfusionsAt(pairs.pairs, values);
        },
        py::arg("pairs"), py::arg("thresholds"), "confusion_at for each threshold (Röhling II)");
}

void BindThresholdLearning(py::module_& m) {
    py::class_<ThresholdTransfer>(m, "ThresholdTransfer",
                                  "A threshold learnt on training pairs, tested on others")
        .def_property_readonly("criterion",
                               [](const ThresholdTransfer& t) { return ToString(t.criterion); })
        .def_readonly("threshold", &ThresholdTransfer::threshold)
        .def_readonly("train_score", &ThresholdTransfer::train_score)
        .def_readonly("train", &ThresholdTransfer::train)
        .def_readonly("test", &ThresholdTransfer::test)
        .def_readonly("test_f1", &ThresholdTransfer::test_f1)
        .def_readonly("test_mcc", &ThresholdTransfer::test_mcc);
    m.def(
        "learn_and_test",
        [](const ScoredPairs& train, const ScoredPairs& test, const std::string& criterion) {
            return LearnAndTest(train.pairs, test.pairs, ParseCriterion(criterion));
        },
        py::arg("train"), py::arg("test"), py::arg("criterion") = "mcc",
        "Learns tau maximising 'mcc' or 'f1' on `train` and applies it to `test`.");
    m.def(
        "learn_on_first_part",
        [](const ScoredPairs& pairs, std::size_t scan_count, double train_fraction,
           const std::string& criterion) {
            ThresholdLearningConfig config;
            config.train_fraction = train_fraction;
            config.criterion = ParseCriterion(criterion);
            return LearnOnFirstPart(pairs.pairs, scan_count, config);
        },
        py::arg("pairs"), py::arg("scan_count"),
        py::arg("train_fraction") = ThresholdLearningConfig{}.train_fraction,
        py::arg("criterion") = "mcc",
        "Learns on the queries before round(train_fraction * scan_count), tests on the rest.");
}

struct BestMatches {
    std::vector<BestMatch> matches;
};

void BindPerScan(py::module_& m) {
    py::class_<BestMatches>(m, "BestMatches",
                            "Per scan its most similar scan outside the gap (Magnusson S̄)")
        .def("__len__", [](const BestMatches& b) { return b.matches.size(); })
        .def_property_readonly(
            "match",
            [](const BestMatches& b) {
                std::vector<long long> v;
                for (const auto& s : b.matches) v.push_back(ScanOrMinusOne(s.match));
                return ArrayOf(v);
            },
            "(N,) int64, -1 when none")
        .def_property_readonly("distance",
                               [](const BestMatches& b) {
                                   std::vector<double> v;
                                   for (const auto& s : b.matches) v.push_back(s.distance);
                                   return ArrayOf(v);
                               })
        .def_property_readonly("second_distance", [](const BestMatches& b) {
            std::vector<double> v;
            for (const auto& s : b.matches) v.push_back(s.second_distance);
            return ArrayOf(v);
        });
    m.def(
        "best_matches",
        [](const py::handle& distances, const GroundTruth& truth) {
            const std::vector<float> condensed = CondensedFrom(distances);
            py::gil_scoped_release release;
            return BestMatches{BestMatchesFromCondensed(condensed, truth)};
        },
        py::arg("distances"), py::arg("truth"),
        "Per scan the best match over all scans outside the gap (ties: smaller index)");
    py::class_<TaxonomyCounts>(m, "TaxonomyCounts", "Scans per label of Magnusson table I")
        .def_readonly("true_positive", &TaxonomyCounts::true_positive)
        .def_readonly("mismatch", &TaxonomyCounts::mismatch)
        .def_readonly("false_positive", &TaxonomyCounts::false_positive)
        .def_readonly("true_negative", &TaxonomyCounts::true_negative)
        .def_readonly("false_negative", &TaxonomyCounts::false_negative)
        .def_property_readonly("overlapping", &TaxonomyCounts::Overlapping)
        .def_property_readonly("non_overlapping", &TaxonomyCounts::NonOverlapping)
        .def_property_readonly("recall", &TaxonomyCounts::Recall)
        .def_property_readonly("false_positive_rate", &TaxonomyCounts::FalsePositiveRate);
    m.def(
        "label_scans",
        [](const BestMatches& matches, const GroundTruth& truth, double t_d) {
            std::vector<std::string> names;
            for (ScanLabel label : LabelScans(matches.matches, truth, t_d))
                names.push_back(ToString(label));
            return names;
        },
        py::arg("matches"), py::arg("truth"), py::arg("t_d"),
        "Magnusson table I label per scan at t_d: 'true_positive', 'mismatch', "
        "'false_positive', 'true_negative', 'false_negative'");
    py::class_<ZeroErrorPoint>(m, "ZeroErrorPoint")
        .def_readonly("t_d", &ZeroErrorPoint::t_d)
        .def_readonly("last_true_positive_distance", &ZeroErrorPoint::last_true_positive_distance)
        .def_readonly("counts", &ZeroErrorPoint::counts)
        .def_readonly("recall", &ZeroErrorPoint::recall);
    py::class_<PerScanEvaluation>(m, "PerScanEvaluation")
        .def_readonly("overlapping", &PerScanEvaluation::overlapping)
        .def_readonly("non_overlapping", &PerScanEvaluation::non_overlapping)
        .def_property_readonly(
            "curve",
            [](const PerScanEvaluation& e) {
                std::vector<double> t_d;
                std::vector<long long> tp, mm, fp, tn, fn;
                for (const TaxonomyPoint& p : e.curve) {
                    t_d.push_back(p.t_d);
                    tp.push_back(static_cast<long long>(p.counts.true_positive));
                    mm.push_back(static_cast<long long>(p.counts.mismatch));
                    fp.push_back(static_cast<long long>(p.counts.false_positive));
                    tn.push_back(static_cast<long long>(p.counts.true_negative));
                    fn.push_back(static_cast<long long>(p.counts.false_negative));
                }
                py::dict curve;
                curve["t_d"] = ArrayOf(t_d);
                curve["true_positive"] = ArrayOf(tp);
                curve["mismatch"] = ArrayOf(mm);
                curve["false_positive"] = ArrayOf(fp);
                curve["true_negative"] = ArrayOf(tn);
                curve["false_negative"] = ArrayOf(fn);
                return curve;
            },
            "counts against t_d (Magnusson fig. 1) as arrays")
        .def_readonly("zero_error", &PerScanEvaluation::zero_error);
    m.def(
        "evaluate_per_scan",
        [](const BestMatches& matches, const GroundTruth& truth, bool mismatches_are_errors) {
            PerScanConfig config;
            config.mismatches_are_errors = mismatches_are_errors;
            py::gil_scoped_release release;
            return EvaluatePerScan(matches.matches, truth, config);
        },
        py::arg("matches"), py::arg("truth"),
        py::arg("mismatches_are_errors") = PerScanConfig{}.mismatches_are_errors,
        "Sweeps t_d over every distinct distance; the recall at zero errors (Magnusson III-B)");
}

void BindEm(py::module_& m) {
    py::class_<EmConfig>(m, "EmConfig", "EM for a 1-D Gaussian mixture (Magnusson II-E)")
        .def(py::init(&FromKeywords<EmConfig>))
        .def_readwrite("components", &EmConfig::components)
        .def_readwrite("restarts", &EmConfig::restarts)
        .def_readwrite("max_iterations", &EmConfig::max_iterations)
        .def_readwrite("tolerance", &EmConfig::tolerance)
        .def_readwrite("min_stddev_fraction", &EmConfig::min_stddev_fraction)
        .def_readwrite("seed", &EmConfig::seed);
    py::class_<DifferenceThreshold>(m, "DifferenceThreshold",
                                    "Magnusson's t_d: the crossing of the first two Gaussians")
        .def_readonly("t_d", &DifferenceThreshold::t_d, "None when they do not cross")
        .def_property_readonly("fitted", &DifferenceThreshold::Fitted)
        .def_readonly("values_used", &DifferenceThreshold::values_used)
        .def_readonly("values_skipped", &DifferenceThreshold::values_skipped)
        .def_property_readonly("weights",
                               [](const DifferenceThreshold& d) {
                                   std::vector<double> v;
                                   for (const auto& c : d.fit.components) v.push_back(c.weight);
                                   return ArrayOf(v);
                               })
        .def_property_readonly(
            "means",
            [](const DifferenceThreshold& d) {
                std::vector<double> v;
                for (const auto& c : d.fit.components) v.push_back(c.mean);
                return ArrayOf(v);
            },
            "ascending")
        .def_property_readonly("stddevs",
                               [](const DifferenceThreshold& d) {
                                   std::vector<double> v;
                                   for (const auto& c : d.fit.components) v.push_back(c.stddev);
                                   return ArrayOf(v);
                               })
        .def_property_readonly("log_likelihood",
                               [](const DifferenceThreshold& d) { return d.fit.log_likelihood; });
    m.def(
        "estimate_difference_threshold",
        [](const py::handle& smallest_differences, std::optional<EmConfig> config) {
            const std::vector<double> values =
                DoublesFrom(smallest_differences, "smallest_differences");
            const EmConfig em = config.value_or(EmConfig{});
            py::gil_scoped_release release;
            return EstimateDifferenceThreshold(values, em);
        },
        py::arg("smallest_differences"), py::arg("config") = py::none(),
        "Fits the mixture to the finite values (each scan's best-match distance) and returns "
        "the crossing of its first two components.");
}

// Field `key` of a candidate of query `query` as T: a missing key is a KeyError, a value of
// another kind a TypeError saying what it must be (not pybind11's "Unable to cast").
template <typename T>
T CandidateField(const py::dict& candidate, const char* key, std::size_t query, const char* what) {
    if (!candidate.contains(key)) {
        throw py::key_error("a candidate of query " + std::to_string(query) + " has no '" + key +
                            "'");
    }
    const py::object value = candidate[key];
    try {
        return value.cast<T>();
    } catch (const py::cast_error&) {
        throw py::type_error("'" + std::string(key) + "' of a candidate of query " +
                             std::to_string(query) + " must be " + what + ", got " +
                             py::repr(value).cast<std::string>());
    }
}

void BindRetrieval(py::module_& m) {
    py::class_<AcceptedLoop>(m, "AcceptedLoop", "One query's first accepted candidate")
        .def_readonly("query", &AcceptedLoop::query)
        .def_readonly("match", &AcceptedLoop::match)
        .def_readonly("rank", &AcceptedLoop::rank)
        .def_readonly("score", &AcceptedLoop::score)
        .def_readonly("correct", &AcceptedLoop::correct)
        .def_readonly("wrong_pose", &AcceptedLoop::wrong_pose);
    py::class_<LoopRetrievalEvaluation>(m, "LoopRetrievalEvaluation",
                                        "Ranked candidates scored against the ground truth")
        .def_readonly("scans", &LoopRetrievalEvaluation::scans)
        .def_readonly("queries", &LoopRetrievalEvaluation::queries)
        .def_readonly("revisiting", &LoopRetrievalEvaluation::revisiting)
        .def_readonly("k", &LoopRetrievalEvaluation::k)
        .def_readonly("hits_at_1", &LoopRetrievalEvaluation::hits_at_1)
        .def_readonly("hits_at_k", &LoopRetrievalEvaluation::hits_at_k)
        .def_readonly("recall_at_1", &LoopRetrievalEvaluation::recall_at_1)
        .def_readonly("recall_at_k", &LoopRetrievalEvaluation::recall_at_k)
        .def_readonly("true_loops", &LoopRetrievalEvaluation::true_loops)
        .def_readonly("false_loops", &LoopRetrievalEvaluation::false_loops)
        .def_readonly("precision", &LoopRetrievalEvaluation::precision)
        .def_readonly("recall", &LoopRetrievalEvaluation::recall)
        .def_readonly("loops_with_pose", &LoopRetrievalEvaluation::loops_with_pose)
        .def_readonly("wrong_pose_loops", &LoopRetrievalEvaluation::wrong_pose_loops)
        .def_property_readonly(
            "recall_at_full_precision",
            [](const LoopRetrievalEvaluation& e) { return e.full_precision.recall; })
        .def_readonly("loops", &LoopRetrievalEvaluation::loops);
    m.def(
        "evaluate_loop_retrieval",
        [](const std::vector<std::pair<std::size_t, py::sequence>>& ranked,
           const GroundTruth& truth, const py::handle& times_s, const py::handle& T_world_sensor,
           std::size_t recall_k, std::optional<double> wrong_pose_m,
           std::optional<double> wrong_pose_deg,
           const std::optional<std::vector<double>>& detector_path_m) {
            std::vector<QueryCandidates> queries;
            for (const auto& [query, candidates] : ranked) {
                QueryCandidates q{query, {}};
                for (const py::handle c : candidates) {
                    // Any mapping (a dict, UserDict, mappingproxy) as a dict; else TypeError.
                    const py::dict d = py::isinstance<py::dict>(c)
                                           ? py::reinterpret_borrow<py::dict>(c)
                                           : py::dict(py::reinterpret_borrow<py::object>(c));
                    RankedCandidate r;
                    r.match = CandidateField<std::size_t>(d, "match", query, "an index >= 0");
                    r.distance = CandidateField<double>(d, "distance", query, "a number");
                    r.accepted = CandidateField<bool>(d, "accepted", query, "True or False");
                    r.score = d.contains("score")
                                  ? CandidateField<double>(d, "score", query, "a number")
                                  : -r.distance;
                    if (d.contains("T_match_query") && !d["T_match_query"].is_none())
                        r.T_match_query = TransformFromArray(d["T_match_query"], "T_match_query");
                    q.ranked.push_back(r);
                }
                queries.push_back(std::move(q));
            }
            LoopRetrievalConfig config;
            config.recall_k = recall_k;
            config.wrong_pose_m = wrong_pose_m.value_or(config.wrong_pose_m);
            config.wrong_pose_deg = wrong_pose_deg.value_or(config.wrong_pose_deg);
            config.Validate();
            const std::vector<core::StampedPose> poses = PosesFromArrays(times_s, T_world_sensor);
            py::gil_scoped_release release;
            return EvaluateLoopRetrieval(queries, truth, poses, config,
                                         detector_path_m.value_or(std::vector<double>{}));
        },
        py::arg("ranked"), py::arg("truth"), py::arg("times_s"), py::arg("T_world_sensor"),
        py::arg("recall_k") = 0, py::arg("wrong_pose_m") = py::none(),
        py::arg("wrong_pose_deg") = py::none(), py::arg("detector_path_m") = py::none(),
        "Scores ranked, decided candidates: `ranked` is a list of (query, [dict(match=, "
        "distance=, accepted=, score= (default -distance), T_match_query= (optional))], best "
        "first); recall@1, recall@k (0: the longest list), precision, recall at full "
        "precision, wrong poses. detector_path_m: the cumulative path (m per scan) the detector "
        "measured a gap in metres on, its odometry's (None: the truth's).");
}

void BindTrajectory(py::module_& m) {
    m.def(
        "absolute_trajectory_rmse",
        [](const py::handle& estimate, const py::handle& truth) {
            const auto est = TransformsFromArray(estimate, "estimate");
            const auto gt = TransformsFromArray(truth, "truth");
            py::gil_scoped_release release;
            return AbsoluteTrajectoryRmse(est, gt);
        },
        py::arg("estimate"), py::arg("truth"),
        "ATE: RMSE (metres) of the positions of `estimate` ((N, 4, 4) T_world_sensor) rigidly "
        "aligned onto `truth`'s (Horn/Umeyama without scale).");
    m.def(
        "align_rigid",
        [](const py::handle& estimate, const py::handle& truth) {
            const auto to_points = [](const py::handle& object, const std::string& what) {
                CheckFloatArray(object, what);
                const auto a = py::array_t<double, py::array::forcecast>::ensure(object);
                if (a.ndim() != 2 || a.shape(1) != 3)
                    throw ShapeError(what + " must have shape (N, 3)");
                std::vector<Eigen::Vector3d> points;
                for (py::ssize_t i = 0; i < a.shape(0); ++i) {
                    points.emplace_back(a.at(i, 0), a.at(i, 1), a.at(i, 2));
                    if (!points.back().allFinite()) {
                        throw NonFiniteError(what + " row " + std::to_string(i) +
                                             " is not finite (NaN or infinite)");
                    }
                }
                return points;
            };
            return TransformToArray(
                AlignRigid(to_points(estimate, "estimate"), to_points(truth, "truth")));
        },
        py::arg("estimate"), py::arg("truth"),
        "The rigid T_truth_estimate (4, 4) minimising sum |truth_i - T estimate_i|^2 over "
        "(N, 3) positions.");
    py::class_<TrajectoryRpe>(m, "TrajectoryRpe", "Relative pose error as KITTI computes it")
        .def_readonly("translation_percent", &TrajectoryRpe::translation_percent)
        .def_readonly("rotation_deg_per_100m", &TrajectoryRpe::rotation_deg_per_100m)
        .def_readonly("segments", &TrajectoryRpe::segments, "0: none long enough (values NaN)");
    m.def(
        "trajectory_rpe",
        [](const py::handle& estimate, const py::handle& truth, const py::object& lengths_m,
           std::optional<std::size_t> step) {
            TrajectoryRpeConfig config;
            if (!lengths_m.is_none()) config.lengths_m = DoublesFrom(lengths_m, "lengths_m");
            config.step = step.value_or(config.step);
            const auto est = TransformsFromArray(estimate, "estimate");
            const auto gt = TransformsFromArray(truth, "truth");
            py::gil_scoped_release release;
            return ComputeTrajectoryRpe(est, gt, config);
        },
        py::arg("estimate"), py::arg("truth"), py::arg("lengths_m") = py::none(),
        py::arg("step") = py::none(),
        "KITTI RPE over segments from every `step`-th pose (default 10) of each length "
        "(default 100..800 m).");
}

}  // namespace

void BindEval(py::module_& m) {
    BindConfusion(m);
    BindGroundTruthConfig(m);
    BindGroundTruth(m);
    BindScoredPairs(m);
    BindPairwise(m);
    BindThresholdLearning(m);
    BindPerScan(m);
    BindEm(m);
    BindRetrieval(m);
    BindTrajectory(m);
}

}  // namespace lidarloop::python
