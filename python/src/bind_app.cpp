// The run layer (lidarloop::app): detect, evaluate and optimise a dataset into a results folder,
// as the CLI's commands do (cli/detect.cpp, cli/evaluate.cpp, cli/optimise.cpp), returning the
// outcome as Python objects.
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/app/heap_reuse.hpp"
#include "lidarloop/app/map_building.hpp"
#include "lidarloop/app/metrics_json.hpp"
#include "lidarloop/app/optimisation.hpp"
#include "lidarloop/app/run_folder.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/io/colour_map.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/io/map_files.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "part2_helpers.hpp"
#include "run_keywords.hpp"

namespace lidarloop::python {
namespace {

namespace fs = std::filesystem;

// ---- what the CLI's option classes do, for keywords ----

/// The dataset keywords (cli/dataset_options.cpp): format auto | kitti | folder | osnabrueck,
/// another poses file, a KITTI calib.txt.
io::Dataset OpenDatasetOf(const fs::path& folder, const std::string& format,
                          const std::optional<fs::path>& poses,
                          const std::optional<fs::path>& calib) {
    io::DatasetOptions options;
    if (format == "kitti") {
        options.format = io::DatasetFormat::kKitti;
    } else if (format == "folder") {
        options.format = io::DatasetFormat::kFolder;
    } else if (format == "osnabrueck") {
        options.format = io::DatasetFormat::kOsnabrueck;
    } else if (format != "auto") {
        throw core::ConfigError("format must be auto, kitti, folder or osnabrueck, got '" + format +
                                "'");
    }
    options.poses_file = poses.value_or(fs::path());
    options.calib_file = calib.value_or(fs::path());
    return io::OpenDataset(folder, options);
}

/// The dataset argument of a run (`name` in messages): a lidarloop.Dataset (open_dataset) as it
/// is, or a folder opened with the dataset keywords (which an opened Dataset does not take).
io::Dataset DatasetOf(const py::object& dataset, const std::string& format,
                      const std::optional<fs::path>& poses, const std::optional<fs::path>& calib,
                      const char* name = "dataset") {
    if (py::isinstance<io::Dataset>(dataset)) {
        if (format != "auto" || poses || calib) {
            throw core::ConfigError(
                "format, poses and calib apply to a dataset folder; this Dataset is open "
                "already (give them to open_dataset)");
        }
        return dataset.cast<io::Dataset>();
    }
    if (!py::isinstance<py::str>(dataset) && !py::hasattr(dataset, "__fspath__")) {
        throw py::type_error(std::string(name) +
                             " must be a folder (str or os.PathLike) or a lidarloop.Dataset");
    }
    return OpenDatasetOf(PathOf(dataset, name), format, poses, calib);
}

/// defaults < config (dict or YAML) < method, as DescriptorOptions::Resolve; the run options
/// come next (ApplyRunKeywords).
io::RunConfig ConfigOf(const py::object& config, const std::optional<std::string>& method) {
    io::RunConfig run = RunConfigFrom(config);
    if (method) run.descriptor.method = pipeline::ParseMethod(*method);
    return run;
}

/// What a run reads besides its scans' folder, which its results may neither lie inside nor
/// replace.
std::vector<fs::path> InputsOf(const io::Dataset& data, const std::optional<fs::path>& poses,
                               const std::optional<fs::path>& calib,
                               std::vector<fs::path> files = {}) {
    // A Dataset object opened with poses or calib files names them too.
    for (const fs::path& file : data.InputFiles()) files.push_back(file);
    files.push_back(poses.value_or(fs::path()));
    files.push_back(calib.value_or(fs::path()));
    return files;
}

/// "lidarloop.detect('seq', out='res', verify=False)": the call as run.json's command line.
std::string CallText(const std::string& function, const py::object& first, const py::dict& given) {
    std::string text = "lidarloop." + function + "(" + py::repr(first).cast<std::string>();
    for (const auto& [key, value] : given) {
        if (value.is_none()) continue;
        text += ", " + py::str(key).cast<std::string>() + "=" + py::repr(value).cast<std::string>();
    }
    return text + ")";
}

/// app::RunInFolder with the GIL released: `out` is checked against `inputs` and staged,
/// `run(staging)` runs, and the folder is completed, or abandoned as failed with the error (then
/// the earlier results stay, or a run.json says so). A progress callback that raised fails the run
/// too, with its exception. Python's KeyboardInterrupt waits until the run returns.
template <typename Run>
auto RunInFolder(const fs::path& out, std::vector<fs::path> inputs, bool overwrite,
                 const std::string& command, const std::string& command_line,
                 const PythonProgress& progress, Run&& run) {
    try {
        py::gil_scoped_release release;
        return app::RunInFolder(
            out, app::CommandRunInfo(command, command_line, std::move(inputs), overwrite),
            [&](const fs::path& staging) {
                auto result = run(staging);
                if (progress.Failed())
                    throw core::Error("the progress callback raised an exception");
                return result;
            });
    } catch (const core::Error&) {
        progress.Rethrow();  // the callback's own exception, when it raised one
        throw;
    }
}

py::object JsonToPython(const nlohmann::json& json) {
    return py::module_::import("json").attr("loads")(json.dump());
}

// ---- detect ----

/// A detection run's outcome with where it was written.
struct DetectResult {
    app::DetectOutcome outcome;
    fs::path out;
    std::string method;
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The rows of loops.csv (one per query with a candidate; app::WriteLoopsCsv) as column arrays.
py::dict LoopsTable(const std::vector<pipeline::LoopQuery>& queries,
                    const std::vector<double>& path_m) {
    std::vector<long long> query, match, rank;
    std::vector<double> distance, second_ratio, path_between_m;
    std::vector<bool> accepted;
    std::vector<core::Transform> poses;
    py::list verifications;
    for (const pipeline::LoopQuery& q : queries) {
        if (!q.has_match()) continue;
        const std::size_t r = q.loop().value_or(0);
        query.push_back(static_cast<long long>(q.query));
        match.push_back(static_cast<long long>(q.candidates[r].index));
        distance.push_back(q.candidates[r].distance);
        second_ratio.push_back(q.second_ratio);
        path_between_m.push_back(
            path_m.empty() ? kNaN : std::abs(path_m[q.query] - path_m[q.candidates[r].index]));
        accepted.push_back(q.accepted);
        rank.push_back(q.verified() ? static_cast<long long>(r + 1) : 0);
        core::Transform T = core::Transform::Identity();
        if (q.verified()) {
            T = q.verifications[r].T_match_query;
            verifications.append(py::cast(q.verifications[r]));
        } else {
            T.matrix().setConstant(kNaN);
            verifications.append(py::none());
        }
        poses.push_back(T);
    }
    py::array_t<bool> accepted_array(static_cast<py::ssize_t>(accepted.size()));
    for (std::size_t k = 0; k < accepted.size(); ++k) accepted_array.mutable_at(k) = accepted[k];
    py::dict table;
    table["query"] = ArrayOf(query);
    table["match"] = ArrayOf(match);
    table["distance"] = ArrayOf(distance);
    table["second_ratio"] = ArrayOf(second_ratio);
    table["accepted"] = accepted_array;
    table["rank"] = ArrayOf(rank);
    table["T_match_query"] = TransformsToArray(poses);
    table["verification"] = verifications;
    table["path_m"] = ArrayOf(path_between_m);
    return table;
}

/// Accepted, verified loops as pose-graph constraints (what `optimise --loops` reads).
std::vector<posegraph::LoopConstraint> AcceptedLoops(
    const std::vector<pipeline::LoopQuery>& queries) {
    std::vector<posegraph::LoopConstraint> loops;
    for (const pipeline::LoopQuery& q : queries) {
        const std::optional<std::size_t> r = q.loop();
        if (!q.accepted || !r || !q.verified()) continue;
        const registration::Verification& v = q.verifications[*r];
        loops.push_back(
            {q.query, q.candidates[*r].index, v.T_match_query, v.overlap.Min(), v.overlap.rmse_m});
    }
    return loops;
}

void BindDetect(py::module_& m) {
    py::class_<DetectResult>(m, "DetectResult", "What `lidarloop detect` found and wrote")
        .def_readonly("out", &DetectResult::out, "the results folder")
        .def_readonly("method", &DetectResult::method)
        .def_property_readonly("threshold",
                               [](const DetectResult& r) { return r.outcome.threshold; })
        .def_property_readonly(
            "accepted", [](const DetectResult& r) { return r.outcome.accepted; },
            "scans whose best match was accepted")
        .def_property_readonly("skipped", [](const DetectResult& r) { return r.outcome.skipped; })
        .def_property_readonly("total_s", [](const DetectResult& r) { return r.outcome.total_s; })
        .def_property_readonly(
            "loops",
            [](const DetectResult& r) { return LoopsTable(r.outcome.queries, r.outcome.path_m); },
            "loops.csv's rows as columns: query, match, distance, second_ratio (NaN: none), "
            "accepted (bool), rank (1-based verified candidate, 0: not verified), "
            "T_match_query (R, 4, 4; NaN when not verified), verification (Verification or "
            "None per row), path_m (path between query and match, metres; NaN: unknown)")
        .def_property_readonly(
            "accepted_loops",
            [](const DetectResult& r) { return AcceptedLoops(r.outcome.queries); },
            "the accepted, verified loops as LoopConstraints (for build_pose_graph)")
        .def_property_readonly(
            "candidates",
            [](const DetectResult& r) {
                std::vector<long long> query, rank, match;
                std::vector<double> distance;
                for (const pipeline::LoopQuery& q : r.outcome.queries) {
                    for (std::size_t k = 0; k < q.candidates.size(); ++k) {
                        query.push_back(static_cast<long long>(q.query));
                        rank.push_back(static_cast<long long>(k + 1));
                        match.push_back(static_cast<long long>(q.candidates[k].index));
                        distance.push_back(q.candidates[k].distance);
                    }
                }
                py::dict table;
                table["query"] = ArrayOf(query);
                table["rank"] = ArrayOf(rank);
                table["match"] = ArrayOf(match);
                table["distance"] = ArrayOf(distance);
                return table;
            },
            "candidates.csv's first columns: query, rank (1-based), match, distance");
    m.def(
        "detect",
        [](const py::object& dataset, const fs::path& out, const std::optional<std::string>& method,
           const py::object& config, bool overwrite, const py::object& progress,
           const std::string& format, const std::optional<fs::path>& poses,
           const std::optional<fs::path>& calib, const std::optional<fs::path>& odometry,
           const std::optional<fs::path>& odometry_calib, const py::kwargs& options) {
            py::dict given(py::arg("out") = out.string(), py::arg("method") = method);
            const PythonProgress python_progress(progress);
            app::DetectRequest request;
            request.config = ConfigOf(config, method);
            ApplyRunKeywords(app::RunCommand::kDetect, options,
                             {&request.config, &request.skip_bad}, given);
            given["overwrite"] = overwrite;
            request.progress = python_progress.Callback();
            request.out = out;
            if (odometry) request.odometry_file = *odometry;
            if (odometry_calib) request.odometry_calib = *odometry_calib;
            const io::Dataset data = DatasetOf(dataset, format, poses, calib);
            std::vector<fs::path> inputs = InputsOf(data, poses, calib);
            if (odometry) inputs.push_back(*odometry);
            if (odometry_calib) inputs.push_back(*odometry_calib);
            DetectResult result;
            result.outcome = RunInFolder(out, std::move(inputs), overwrite, "detect",
                                         CallText("detect", dataset, given), python_progress,
                                         [&](const fs::path& staging) {
                                             app::DetectRequest staged = request;
                                             staged.out = staging;
                                             return app::RunDetect(data, staged);
                                         });
            result.out = out;
            result.method = core::ToString(request.config.descriptor.method);
            return result;
        },
        py::arg("dataset"), py::kw_only(), py::arg("out"), py::arg("method") = py::none(),
        py::arg("config") = py::none(), py::arg("overwrite") = false,
        py::arg("progress") = py::none(), py::arg("format") = "auto", py::arg("poses") = py::none(),
        py::arg("calib") = py::none(), py::arg("odometry") = py::none(),
        py::arg("odometry_calib") = py::none(),
        RunDoc(
            app::RunCommand::kDetect,
            "`lidarloop detect DATASET --out OUT` on a dataset folder (or a Dataset of "
            "open_dataset): describes every scan, finds each scan's "
            "candidates, verifies them (unless verify=False or the config says so) and writes "
            "loops.csv, candidates.csv, the similarity matrix and images, database.lldb, "
            "config.yaml, timings.json and run.json into `out` (a results folder: refused inside "
            "the dataset or when it holds other files, unless overwrite=True). None keeps the "
            "config's value. progress(stage, done, total) is called from worker threads, one call "
            "at "
            "a time, with done rising to total in each stage."));
}

// ---- evaluate ----

struct EvaluateResult {
    app::EvaluationOutcome outcome;
    fs::path out;
    std::string dataset;
    std::size_t scans = 0;
};

/// The full (n, n) float32 distance matrix (diagonal 0) of a similarity matrix.
py::array_t<float> FullMatrix(const pipeline::SimilarityMatrix& matrix) {
    const auto n = static_cast<py::ssize_t>(matrix.size());
    py::array_t<float> full({n, n});
    auto out = full.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i) {
        out(i, i) = 0.0f;
        for (py::ssize_t j = i + 1; j < n; ++j) {
            const float d = matrix.at(static_cast<std::size_t>(i), static_cast<std::size_t>(j));
            out(i, j) = d;
            out(j, i) = d;
        }
    }
    return full;
}

void BindMethodEvaluation(py::module_& m) {
    using app::MethodEvaluation;
    py::class_<MethodEvaluation>(m, "MethodEvaluation",
                                 "Everything `lidarloop evaluate` computed for one method")
        .def_readonly("name", &MethodEvaluation::name, "height, range, ndt or results:<file>")
        .def_readonly("default_threshold", &MethodEvaluation::default_threshold)
        .def_property_readonly(
            "similarity",
            [](const MethodEvaluation& e) -> std::optional<py::array_t<float>> {
                if (e.matrix.size() == 0) return std::nullopt;  // beyond the memory budget
                return FullMatrix(e.matrix);
            },
            "(n, n) float32 descriptor distances (W or sigma'), diagonal 0; None when the "
            "matrix would exceed output.similarity_matrix_mib (the evaluation streams the pairs)")
        .def_readonly("pairwise", &MethodEvaluation::pairwise, "Röhling IV-B/C")
        .def_readonly("learnt", &MethodEvaluation::learnt, "Röhling table I, or None")
        .def_readonly("learnt_on", &MethodEvaluation::learnt_on)
        .def_readonly("at_default", &MethodEvaluation::at_default)
        .def_readonly("fixed_thresholds", &MethodEvaluation::fixed_thresholds)
        .def_readonly("at_fixed", &MethodEvaluation::at_fixed)
        .def_readonly("per_scan", &MethodEvaluation::per_scan, "Magnusson table I, fig. 1")
        .def_readonly("per_scan_at_default", &MethodEvaluation::per_scan_at_default)
        .def_readonly("em", &MethodEvaluation::em, "Magnusson fig. 2")
        .def_property_readonly(
            "retrieval",
            [](const MethodEvaluation& e) -> py::object {
                if (!e.retrieval) return py::none();
                return py::cast(e.retrieval->descriptor);
            },
            "the top-k candidates scored as the descriptor decides them (LoopRetrievalEvaluation)")
        .def_property_readonly(
            "retrieval_verified",
            [](const MethodEvaluation& e) -> py::object {
                if (!e.retrieval || !e.retrieval->verified) return py::none();
                return py::cast(*e.retrieval->verified);
            },
            "the same after geometric verification; None when verification is off")
        .def_readonly("describe_ms_per_scan_median", &MethodEvaluation::describe_ms_per_scan_median)
        .def_readonly("ns_per_comparison", &MethodEvaluation::ns_per_comparison)
        .def_property_readonly(
            "metrics", [](const MethodEvaluation& e) { return JsonToPython(app::MetricsJson(e)); },
            "this method's entry of metrics.json, as a dict");
}

void BindEvaluate(py::module_& m) {
    py::class_<EvaluateResult>(m, "EvaluateResult", "What `lidarloop evaluate` computed and wrote")
        .def_readonly("out", &EvaluateResult::out)
        .def_property_readonly("metrics_path",
                               [](const EvaluateResult& r) { return r.out / "metrics.json"; })
        .def_property_readonly("truth", [](const EvaluateResult& r) { return r.outcome.truth; })
        .def_property_readonly(
            "methods",
            [](const EvaluateResult& r) {
                py::dict methods;
                for (const app::MethodEvaluation& e : r.outcome.methods)
                    methods[py::str(e.name)] = py::cast(e);
                return methods;
            },
            "name -> MethodEvaluation, in the order evaluated")
        .def_property_readonly("notes", [](const EvaluateResult& r) { return r.outcome.notes; })
        .def_property_readonly(
            "skipped", [](const EvaluateResult& r) { return r.outcome.skipped; },
            "'scan 17: <reason>' per scan that could not be read (skip_bad=True)")
        .def_property_readonly(
            "metrics",
            [](const EvaluateResult& r) {
                return JsonToPython(app::EvaluationMetricsJson(r.dataset, r.scans, r.outcome));
            },
            "the whole metrics.json as a dict");
    m.def(
        "evaluate",
        [](const py::object& dataset, const fs::path& out,
           const std::optional<std::vector<std::string>>& methods, const py::object& config,
           const std::vector<fs::path>& results, bool overwrite, const py::object& progress,
           const std::string& format, const std::optional<fs::path>& poses,
           const std::optional<fs::path>& calib, const py::object& train_on,
           const std::optional<fs::path>& odometry, const std::optional<fs::path>& odometry_calib,
           const py::kwargs& options) {
            py::dict given(py::arg("out") = out.string(), py::arg("methods") = methods);
            const PythonProgress python_progress(progress);
            app::EvaluationRequest request;
            for (const std::string& name : methods.value_or(pipeline::MethodNames()))
                request.methods.push_back(pipeline::ParseMethod(name));
            request.config = ConfigOf(config, std::nullopt);
            ApplyRunKeywords(app::RunCommand::kEvaluate, options,
                             {&request.config, &request.skip_bad, &request}, given);
            given["overwrite"] = overwrite;
            for (const fs::path& file : results) request.results_files.push_back(file.string());
            request.progress = python_progress.Callback();
            request.out = out;
            if (odometry) request.odometry_file = *odometry;
            if (odometry_calib) request.odometry_calib = *odometry_calib;
            const io::Dataset data = DatasetOf(dataset, format, poses, calib);
            // --train-on: learn each method's threshold on another dataset (with poses).
            std::optional<io::Dataset> train_data;
            if (!train_on.is_none())
                train_data = DatasetOf(train_on, "auto", std::nullopt, std::nullopt, "train_on");
            EvaluateResult result;
            std::vector<fs::path> inputs = InputsOf(data, poses, calib);
            inputs.insert(inputs.end(), results.begin(), results.end());
            if (train_data) {
                for (const fs::path& file : train_data->InputFiles()) inputs.push_back(file);
            }
            if (odometry) inputs.push_back(*odometry);
            if (odometry_calib) inputs.push_back(*odometry_calib);
            result.outcome = RunInFolder(
                out, std::move(inputs), overwrite, "evaluate", CallText("evaluate", dataset, given),
                python_progress, [&](const fs::path& staging) {
                    app::EvaluationRequest staged = request;
                    staged.out = staging;
                    return app::RunEvaluation(data, staged, train_data ? &*train_data : nullptr);
                });
            result.out = out;
            result.dataset = data.root().string();
            result.scans = data.size();
            return result;
        },
        py::arg("dataset"), py::kw_only(), py::arg("out"), py::arg("methods") = py::none(),
        py::arg("config") = py::none(), py::arg("results") = std::vector<fs::path>{},
        py::arg("overwrite") = false, py::arg("progress") = py::none(), py::arg("format") = "auto",
        py::arg("poses") = py::none(), py::arg("calib") = py::none(),
        py::arg("train_on") = py::none(), py::arg("odometry") = py::none(),
        py::arg("odometry_calib") = py::none(),
        RunDoc(
            app::RunCommand::kEvaluate,
            "`lidarloop evaluate DATASET --out OUT`: scores every method (default all) and "
            "results file on one ground truth from the dataset's poses (distance_m, "
            "max_heading_deg, the config's min gap) and writes metrics.json, roc.csv, pr.csv, "
            "images, report.md, config.yaml and run.json into `out` (a results folder, as "
            "detect's). train_on (a folder or Dataset with poses) learns each method's threshold "
            "there instead of on the first part. odometry (a KITTI or TUM file, never the ground "
            "truth): verification with submaps and the odometry gate, as detect's; without it "
            "the scans' registrations to their neighbours place the submaps (dense scans: "
            "none either way). None keeps "
            "the default of app::EvaluationRequest or the config."));
}

// ---- optimise ----

struct OptimiseResult {
    app::OptimiseOutcome outcome;
    fs::path out;
};

py::object TrajectoryMetricsOf(const std::optional<app::TrajectoryMetrics>& metrics) {
    if (!metrics) return py::none();
    py::dict d;
    d["ate_rmse_m"] = metrics->ate_rmse_m;
    d["rpe_translation_percent"] = metrics->rpe.translation_percent;
    d["rpe_rotation_deg_per_100m"] = metrics->rpe.rotation_deg_per_100m;
    d["rpe_segments"] = metrics->rpe.segments;
    return d;
}

void BindOptimise(py::module_& m) {
    py::class_<OptimiseResult>(m, "OptimiseResult", "What `lidarloop optimise` did and wrote")
        .def_readonly("out", &OptimiseResult::out)
        .def_property_readonly("metrics_path",
                               [](const OptimiseResult& r) { return r.out / "metrics.json"; })
        .def_property_readonly(
            "loops", [](const OptimiseResult& r) { return r.outcome.loops; },
            "the accepted loops, as read or detected")
        .def_property_readonly(
            "result", [](const OptimiseResult& r) { return r.outcome.result; },
            "the OptimisationResult (optimised poses, per-loop verdicts)")
        .def_property_readonly(
            "poses",
            [](const OptimiseResult& r) { return TransformsToArray(r.outcome.result.poses); },
            "(N, 4, 4) optimised T_world_sensor")
        .def_property_readonly("loop_is_true",
                               [](const OptimiseResult& r) { return r.outcome.loop_is_true; })
        .def_property_readonly(
            "odometry_metrics",
            [](const OptimiseResult& r) { return TrajectoryMetricsOf(r.outcome.odometry); },
            "ATE RMSE and RPE of the odometry against the ground truth (None without it)")
        .def_property_readonly(
            "optimised_metrics",
            [](const OptimiseResult& r) { return TrajectoryMetricsOf(r.outcome.optimised); })
        .def_property_readonly(
            "maps",
            [](const OptimiseResult& r) {
                py::dict d;
                d["voxel_m"] = r.outcome.maps.voxel_m;
                d["points_odometry"] = r.outcome.maps.odometry_points;
                d["points_optimised"] = r.outcome.maps.optimised_points;
                d["seconds"] = r.outcome.maps.seconds;
                return d;
            },
            "map_odometry.ply and map_optimised.ply: voxel_m, points_odometry, "
            "points_optimised, seconds")
        .def_property_readonly("notes", [](const OptimiseResult& r) { return r.outcome.notes; })
        .def_property_readonly("total_s",
                               [](const OptimiseResult& r) { return r.outcome.total_s; });
    m.def(
        "optimise",
        [](const py::object& dataset, const fs::path& odometry, const fs::path& out,
           const std::optional<fs::path>& loops, const std::string& pose_format,
           const std::optional<std::string>& method, const py::object& config, bool overwrite,
           const py::object& progress, const std::string& format,
           const std::optional<fs::path>& poses, const std::optional<fs::path>& calib,
           const std::optional<fs::path>& odometry_calib, const py::kwargs& options) {
            py::dict given(py::arg("odometry") = odometry.string(), py::arg("out") = out.string(),
                           py::arg("method") = method);
            if (pose_format != "kitti" && pose_format != "tum")
                throw core::ConfigError("pose_format must be kitti or tum, got '" + pose_format +
                                        "'");
            const PythonProgress python_progress(progress);
            app::OptimiseRequest request;
            request.config = ConfigOf(config, method);
            ApplyRunKeywords(app::RunCommand::kOptimise, options,
                             {&request.config, &request.skip_bad}, given);
            given["overwrite"] = overwrite;
            request.odometry_file = odometry;
            if (odometry_calib) request.odometry_calib = *odometry_calib;
            request.loops_file = loops.value_or(fs::path());
            request.format = pose_format == "tum" ? app::PoseFormat::kTum : app::PoseFormat::kKitti;
            request.progress = python_progress.Callback();
            request.out = out;
            const io::Dataset data = DatasetOf(dataset, format, poses, calib);
            OptimiseResult result;
            result.outcome =
                RunInFolder(out,
                            InputsOf(data, poses, calib,
                                     {odometry, request.loops_file, request.odometry_calib}),
                            overwrite, "optimise", CallText("optimise", dataset, given),
                            python_progress, [&](const fs::path& staging) {
                                app::OptimiseRequest staged = request;
                                staged.out = staging;
                                return app::RunOptimisation(data, staged);
                            });
            result.out = out;
            return result;
        },
        py::arg("dataset"), py::kw_only(), py::arg("odometry"), py::arg("out"),
        py::arg("loops") = py::none(), py::arg("pose_format") = "kitti",
        py::arg("method") = py::none(), py::arg("config") = py::none(),
        py::arg("overwrite") = false, py::arg("progress") = py::none(), py::arg("format") = "auto",
        py::arg("poses") = py::none(), py::arg("calib") = py::none(),
        py::arg("odometry_calib") = py::none(),
        RunDoc(
            app::RunCommand::kOptimise,
            "`lidarloop optimise DATASET --odometry FILE --out OUT`: reads the accepted loops "
            "(loops.csv of a verified detect) or detects them first (into out/detection), builds "
            "and optimises the pose graph and writes poses_optimised.txt (pose_format kitti | "
            "tum), graph.g2o, loop_verdicts.csv, metrics.json, report.md, config.yaml, "
            "map_odometry.ply, map_optimised.ply and map.png into `out` "
            "(a results folder, as detect's: staged, run.json last, refused inside the dataset or "
            "when it holds other files unless overwrite)."));
}

// ---- maps ----

/// A map's settings: defaults < config (dict or YAML) < voxel_m, max_points.
core::MapConfig MapConfigOf(const py::object& config, std::optional<double> voxel_m,
                            std::optional<std::size_t> max_points) {
    core::MapConfig map = RunConfigFrom(config).map;
    map.voxel_m = voxel_m.value_or(map.voxel_m);
    map.max_points = max_points.value_or(map.max_points);
    map.Validate();
    return map;
}

/// A trajectory argument: None (the dataset's poses), a KITTI or TUM file, or an (N, 4, 4) array
/// of T_world_sensor (times: the scan index).
std::vector<core::StampedPose> TrajectoryOf(const io::Dataset& data, const py::object& trajectory) {
    if (trajectory.is_none()) return app::MapTrajectory(data, {});
    if (py::isinstance<py::str>(trajectory) || py::hasattr(trajectory, "__fspath__"))
        return app::MapTrajectory(data, PathOf(trajectory, "trajectory"));
    const std::vector<core::Transform> transforms = TransformsFromArray(trajectory, "trajectory");
    std::vector<core::StampedPose> poses(transforms.size());
    for (std::size_t i = 0; i < poses.size(); ++i)
        poses[i] = {static_cast<double>(i), transforms[i], std::nullopt};
    return poses;
}

py::dict MapCloudToPython(const core::MapCloud& map) {
    const auto n = static_cast<py::ssize_t>(map.points.size());
    py::array_t<double> points({n, py::ssize_t{3}});
    py::array_t<double> times(n);
    py::array_t<std::uint8_t> colors({n, py::ssize_t{3}});
    auto p = points.mutable_unchecked<2>();
    auto t = times.mutable_unchecked<1>();
    auto c = colors.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i) {
        const core::MapPoint& point = map.points[static_cast<std::size_t>(i)];
        const io::Rgb rgb = io::Viridis(io::MapTimeFraction(map, point.time_s));
        for (int k = 0; k < 3; ++k) {
            p(i, k) = point.position[k];
            c(i, k) = rgb[static_cast<std::size_t>(k)];
        }
        t(i) = point.time_s;
    }
    py::dict d;
    d["points"] = points;
    d["times_s"] = times;
    d["colors"] = colors;
    d["voxel_m"] = map.voxel_m;
    d["scans"] = map.scans;
    d["input_points"] = map.input_points;
    return d;
}

void BindMap(py::module_& m) {
    m.def(
        "build_map",
        [](const py::object& dataset, const py::object& trajectory, std::optional<double> voxel_m,
           std::optional<std::size_t> max_points, const py::object& config,
           const std::vector<std::size_t>& scans, bool skip_bad, const py::object& progress,
           const std::string& format, const std::optional<fs::path>& poses,
           const std::optional<fs::path>& calib) {
            const io::Dataset data = DatasetOf(dataset, format, poses, calib);
            const core::MapConfig map_config = MapConfigOf(config, voxel_m, max_points);
            const std::vector<core::StampedPose> placed = TrajectoryOf(data, trajectory);
            const PythonProgress python_progress(progress);
            app::MapBuildOptions options;
            options.scans = scans;
            options.skip_bad = skip_bad;
            options.progress = python_progress.Callback();
            app::BuiltMaps built;
            {
                py::gil_scoped_release release;
                built = app::BuildMaps(data, {placed}, map_config, options);
            }
            python_progress.Rethrow();
            py::dict result = MapCloudToPython(built.maps.front());
            result["skipped"] = built.skipped;
            return result;
        },
        py::arg("dataset"), py::kw_only(), py::arg("trajectory") = py::none(),
        py::arg("voxel_m") = py::none(), py::arg("max_points") = py::none(),
        py::arg("config") = py::none(), py::arg("scans") = std::vector<std::size_t>{},
        py::arg("skip_bad") = false, py::arg("progress") = py::none(), py::arg("format") = "auto",
        py::arg("poses") = py::none(), py::arg("calib") = py::none(),
        "Every scan of the dataset (or `scans`, in that order) placed with `trajectory` (None: "
        "the dataset's poses; a KITTI or TUM file read as optimise reads odometry; or an (N, 4, "
        "4) array of T_world_sensor, times the scan index) and averaged into voxels "
        "(app::BuildMaps): a dict with points (M, 3) float64, times_s (M,), colors (M, 3) uint8 "
        "(viridis of the scan time), voxel_m (coarser than asked when max_points capped it), "
        "scans, input_points and skipped.");
    m.def(
        "write_map",
        [](const py::object& dataset, const fs::path& out,
           const std::optional<fs::path>& trajectory, std::optional<double> voxel_m,
           std::optional<std::size_t> max_points, const py::object& config, bool overwrite,
           const py::object& progress, const std::string& format,
           const std::optional<fs::path>& poses, const std::optional<fs::path>& calib,
           const std::optional<fs::path>& trajectory_calib) {
            const io::Dataset data = DatasetOf(dataset, format, poses, calib);
            const PythonProgress python_progress(progress);
            app::MapRequest request;
            request.poses_file = trajectory.value_or(fs::path());
            // `lidarloop map --poses T --calib C`: `calib` is the dataset's, as everywhere.
            request.calib_file = trajectory_calib.value_or(fs::path());
            request.config = MapConfigOf(config, voxel_m, max_points);
            request.out = out;
            request.inputs = InputsOf(data, poses, calib);
            request.overwrite = overwrite;
            request.progress = python_progress.Callback();
            app::MapOutcome outcome;
            {
                py::gil_scoped_release release;
                outcome = app::RunMap(data, request);
            }
            python_progress.Rethrow();
            py::dict result;
            result["out"] = out;
            result["points"] = outcome.points;
            result["voxel_m"] = outcome.voxel_m;
            result["scans"] = outcome.scans;
            result["input_points"] = outcome.input_points;
            result["notes"] = outcome.notes;
            result["total_s"] = outcome.total_s;
            return result;
        },
        py::arg("dataset"), py::kw_only(), py::arg("out"), py::arg("trajectory") = py::none(),
        py::arg("voxel_m") = py::none(), py::arg("max_points") = py::none(),
        py::arg("config") = py::none(), py::arg("overwrite") = false,
        py::arg("progress") = py::none(), py::arg("format") = "auto", py::arg("poses") = py::none(),
        py::arg("calib") = py::none(), py::arg("trajectory_calib") = py::none(),
        "`lidarloop map DATASET --poses TRAJECTORY --out OUT`: the map of the dataset placed "
        "with `trajectory` (a KITTI or TUM file, its KITTI poses converted from KITTI's camera "
        "frame by `trajectory_calib` when given, as map's --calib; None: the dataset's poses, "
        "which `calib` converts as for every dataset) written as a binary "
        "PLY coloured by scan time (app::RunMap: `out` is refused inside an input, and replaced "
        "only when lidarloop wrote it unless overwrite). A dict: out, points, voxel_m, scans, "
        "input_points, notes, total_s.");
}

}  // namespace

void BindApp(py::module_& m) {
    BindRunOptions(m);
    BindDetect(m);
    BindMethodEvaluation(m);
    BindEvaluate(m);
    BindOptimise(m);
    BindMap(m);
    m.def("keep_freed_memory_for_reuse", &app::KeepFreedMemoryForReuse,
          "What the lidarloop tool does first (app::KeepFreedMemoryForReuse): glibc's allocator "
          "keeps up to 64 MiB of freed memory for the next scan instead of faulting a dense "
          "scan's megabytes in again (reading a 115k-point scan 0.6 ms instead of 11). For the "
          "whole process, so not done on import; True when the allocator took the settings.");
}

}  // namespace lidarloop::python
