#include "lidarloop/app/run_options.hpp"

#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/core/number_text.hpp"

namespace lidarloop::app {
namespace {

constexpr auto kDetect = static_cast<std::uint8_t>(RunCommand::kDetect);
constexpr auto kEvaluate = static_cast<std::uint8_t>(RunCommand::kEvaluate);
constexpr auto kOptimise = static_cast<std::uint8_t>(RunCommand::kOptimise);
constexpr auto kBench = static_cast<std::uint8_t>(RunCommand::kBench);
constexpr std::uint8_t kDetecting = kDetect | kEvaluate | kOptimise | kBench;
constexpr std::uint8_t kRunning = kDetect | kEvaluate | kOptimise;  // read a whole dataset
// optimise always verifies: the pose graph needs the loops' poses.
constexpr std::uint8_t kMayNotVerify = kDetect | kEvaluate | kBench;
constexpr RunCommand kCommands[] = {RunCommand::kDetect, RunCommand::kEvaluate,
                                    RunCommand::kOptimise, RunCommand::kBench};

std::string Code(std::string_view text) { return "`" + std::string(text) + "`"; }

// A table cell's text: a | would end the cell.
std::string Cell(std::string_view text) {
    std::string cell;
    for (const char c : text) cell += c == '|' ? std::string("\\|") : std::string(1, c);
    return cell;
}

double AsNumber(const RunOptionValue& v) { return std::get<double>(v); }
const std::string& AsName(const RunOptionValue& v) { return std::get<std::string>(v); }

EvaluationRequest& Evaluation(const RunTargets& t) {
    if (t.evaluation == nullptr) throw core::Error("run option of evaluate applied elsewhere");
    return *t.evaluation;
}

// The one table. A row's apply and default read the config or request member it sets; nothing
// else names it.
std::vector<RunOption> MakeRunOptions() {
    using T = RunOptionType;
    return {
        {"threshold", "--threshold", "T", T::kNumber,
         "decision threshold: tau (height, range), t_d (ndt) or d (scancontext)",
         "detection.threshold", kDetecting,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->detection.threshold = AsNumber(v);
         },
         [] {
             const auto t = io::RunConfig{}.detection.threshold;
             return t ? core::NumberText(*t) : std::string("the method's");
         }},
        {"min_gap", "--min-gap", "S", T::kNumber,
         "S: candidates at least this far back (evaluate: pairs closer in the sequence are not "
         "evaluated)",
         "detection.min_gap", kDetecting,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->detection.min_gap.value = AsNumber(v);
         },
         [] { return core::NumberText(io::RunConfig{}.detection.min_gap.value); }},
        {"min_gap_unit", "--min-gap-unit", "UNIT", T::kName,
         "unit of the gap: scans | seconds | metres (of path, from the poses or odometry)",
         "detection.min_gap_unit", kDetecting,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->detection.min_gap.unit = core::ParseMinGapUnit(AsName(v));
         },
         [] { return Code(core::ToString(io::RunConfig{}.detection.min_gap.unit)); }},
        {"min_path_m", "--min-path", "M", T::kNumber,
         "and more than this much path back (metres, on the odometry or the poses, where known; "
         "evaluate: closer pairs are no revisits); 0: no path rule",
         "detection.min_path_m", kDetecting,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->detection.min_path_m = AsNumber(v);
         },
         [] { return core::NumberText(io::RunConfig{}.detection.min_path_m); }},
        {"top_k", "--top-k", "K", T::kInt, "candidates per query scan, each verified",
         "detection.top_k", kDetecting,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->detection.top_k = std::get<int>(v);
         },
         [] { return std::to_string(io::RunConfig{}.detection.top_k); }},
        {"verify", "--no-verify", "", T::kSwitchOff,
         "descriptor only: accept by the threshold, no geometric verification (keyword: False)",
         "detection.verify", kMayNotVerify,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->detection.verify = std::get<bool>(v);
         },
         [] { return std::string(io::RunConfig{}.detection.verify ? "verify" : "no-verify"); }},
        {"stop_at_first_loop", "--all-candidates", "", T::kSwitchOff,
         "register every candidate, not only those up to the first loop in rank order (slower; "
         "the loop is the accepted one that overlaps most; keyword: stop_at_first_loop=False)",
         "detection.stop_at_first_loop", kDetecting,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->detection.stop_at_first_loop = std::get<bool>(v);
         },
         [] { return std::string(io::RunConfig{}.detection.stop_at_first_loop ? "stop" : "all"); }},
        {"skip_bad", "--skip-bad", "", T::kSwitch,
         "skip unreadable scans instead of stopping (listed in skipped.txt)",
         "the request's skip_bad", kRunning,
         [](const RunTargets& t, const RunOptionValue& v) {
             if (t.skip_bad != nullptr) *t.skip_bad = std::get<bool>(v);
         },
         [] { return std::string(EvaluationRequest{}.skip_bad ? "skip" : "stop"); }},
        {"max_odometry_step_m", "--max-odometry-step", "M", T::kNumber,
         "odometry moving farther than this between two scans is an error (a jump or a reset), "
         "metres",
         "posegraph.max_odometry_step_m", kOptimise,
         [](const RunTargets& t, const RunOptionValue& v) {
             t.config->posegraph.max_odometry_step_m = AsNumber(v);
         },
         [] { return core::NumberText(io::RunConfig{}.posegraph.max_odometry_step_m); }},
        {"distance_m", "--distance", "D", T::kNumber,
         "same place when the sensors are closer than this, metres (Roehling 10, Magnusson 3-10)",
         "the ground truth", kEvaluate,
         [](const RunTargets& t, const RunOptionValue& v) {
             Evaluation(t).distance_m = AsNumber(v);
         },
         [] { return core::NumberText(EvaluationRequest{}.distance_m); }},
        {"max_heading_deg", "--max-heading", "DEG", T::kNumber,
         "and their headings differ by less than this, degrees (0: any; Kvarntorp 20)",
         "the ground truth", kEvaluate,
         [](const RunTargets& t, const RunOptionValue& v) {
             Evaluation(t).max_heading_deg = AsNumber(v);
         },
         [] { return core::NumberText(EvaluationRequest{}.max_heading_deg); }},
        {"train_fraction", "--train-fraction", "F", T::kNumber,
         "share of the sequence a threshold is learnt on", "threshold learning", kEvaluate,
         [](const RunTargets& t, const RunOptionValue& v) {
             Evaluation(t).learning.train_fraction = AsNumber(v);
         },
         [] { return core::NumberText(EvaluationRequest{}.learning.train_fraction); }},
        {"criterion", "--criterion", "mcc|f1", T::kName,
         "what the learnt threshold maximises: mcc | f1", "threshold learning", kEvaluate,
         [](const RunTargets& t, const RunOptionValue& v) {
             Evaluation(t).learning.criterion = eval::ParseCriterion(AsName(v));
         },
         [] { return Code(eval::ToString(EvaluationRequest{}.learning.criterion)); }},
        {"fixed_thresholds", "--fixed-thresholds", "T,T,...", T::kNumbers,
         "also report MCC and F1 at these thresholds (Roehling table II)", "the report", kEvaluate,
         [](const RunTargets& t, const RunOptionValue& v) {
             Evaluation(t).fixed_thresholds = std::get<std::vector<double>>(v);
         },
         [] {
             std::string text;
             for (const double t : EvaluationRequest{}.fixed_thresholds)
                 text += (text.empty() ? "" : ", ") + core::NumberText(t);
             return text.empty() ? std::string("none") : text;
         }},
    };
}

}  // namespace

std::string_view NameOf(RunCommand command) {
    switch (command) {
        case RunCommand::kDetect:
            return "detect";
        case RunCommand::kEvaluate:
            return "evaluate";
        case RunCommand::kOptimise:
            return "optimise";
        case RunCommand::kBench:
            return "bench";
    }
    return "";
}

RunCommand RunCommandOf(std::string_view name) {
    for (const RunCommand command : kCommands) {
        if (NameOf(command) == name) return command;
    }
    throw core::ConfigError("no run command '" + std::string(name) +
                            "' (detect, evaluate, optimise or bench)");
}

const std::vector<RunOption>& RunOptions() {
    static const std::vector<RunOption> options = MakeRunOptions();
    return options;
}

std::vector<const RunOption*> RunOptionsOf(RunCommand command) {
    std::vector<const RunOption*> taken;
    for (const RunOption& option : RunOptions()) {
        if (option.TakenBy(command)) taken.push_back(&option);
    }
    return taken;
}

void ApplyRunOption(const RunOption& option, const RunOptionValue& value, const RunTargets& targets,
                    bool by_keyword) {
    try {
        option.apply(targets, value);
        // The config was valid before: what is wrong now came through this option.
        targets.config->Validate();
        if (targets.evaluation) {
            GroundTruthRule(*targets.evaluation);  // validates the rule
            targets.evaluation->learning.Validate();
        }
    } catch (const core::ConfigError& e) {
        // Say which option the bad name or value came through, then what the config says.
        throw core::ConfigError(std::string(by_keyword ? option.keyword : option.flag) + ": " +
                                e.what());
    }
}

std::string RunOptionsMarkdown() {
    std::string text =
        "| flag | Python keyword | commands | sets | default | meaning |\n"
        "|---|---|---|---|---|---|\n";
    for (const RunOption& o : RunOptions()) {
        std::string commands;
        for (const RunCommand command : kCommands) {
            if (o.TakenBy(command))
                commands += (commands.empty() ? "" : ", ") + Code(NameOf(command));
        }
        std::string flag(o.flag);
        if (!o.value_name.empty()) flag += " " + std::string(o.value_name);
        const bool key = o.sets.find(' ') == std::string_view::npos;
        text += "| " + Code(Cell(flag)) + " | " + Code(o.keyword) + " | " + commands + " | " +
                (key ? Code(o.sets) : std::string(o.sets)) + " | " + o.default_text() + " | " +
                Cell(o.help) + " |\n";
    }
    return text;
}

}  // namespace lidarloop::app
