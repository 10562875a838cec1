// The pose graph (lidarloop::posegraph): built from odometry and loops, optimised with Ceres,
// written as g2o; loops read from a loops.csv.
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/io/pose_graph_files.hpp"
#include "lidarloop/posegraph/optimiser.hpp"
#include "lidarloop/posegraph/pose_graph.hpp"
#include "part2_helpers.hpp"

namespace lidarloop::python {
namespace {

using posegraph::Edge;
using posegraph::LoopConstraint;
using posegraph::LoopResult;
using posegraph::OptimisationResult;
using posegraph::PoseGraph;

// The posegraph section of a run configuration (None, dict or YAML path).
posegraph::PoseGraphConfig PoseGraphConfigFrom(const py::object& config) {
    posegraph::PoseGraphConfig graph = RunConfigFrom(config).posegraph;
    graph.Validate();
    return graph;
}

std::string KindName(Edge::Kind kind) { return kind == Edge::Kind::kLoop ? "loop" : "odometry"; }

void BindLoopConstraint(py::module_& m) {
    py::class_<LoopConstraint>(m, "LoopConstraint",
                               "An accepted loop: scan `query` seen from scan `match`.")
        .def(py::init([](std::size_t query, std::size_t match, const py::handle& T_match_query,
                         double overlap, double rmse_m) {
                 return LoopConstraint{query, match,
                                       TransformFromArray(T_match_query, "T_match_query"), overlap,
                                       rmse_m};
             }),
             py::arg("query"), py::arg("match"), py::arg("T_match_query"),
             py::arg("overlap") = std::numeric_limits<double>::quiet_NaN(),
             py::arg("rmse_m") = std::numeric_limits<double>::quiet_NaN())
        .def_readonly("query", &LoopConstraint::query)
        .def_readonly("match", &LoopConstraint::match)
        .def_property_readonly(
            "T_match_query",
            [](const LoopConstraint& l) { return TransformToArray(l.T_match_query); },
            "(4, 4) float64: maps query-frame points into the match frame, metres")
        .def_readonly("overlap", &LoopConstraint::overlap,
                      "the verification's smaller overlap fraction; NaN when unknown")
        .def_readonly("rmse_m", &LoopConstraint::rmse_m,
                      "the verification's RMS plane distance, metres; NaN when unknown")
        .def("__repr__", [](const LoopConstraint& l) {
            return "<LoopConstraint query=" + std::to_string(l.query) +
                   " match=" + std::to_string(l.match) + ">";
        });
}

void BindGraph(py::module_& m) {
    py::class_<Edge>(m, "Edge",
                     "A relative-pose measurement (g2o EDGE_SE3:QUAT): T_from_to is the pose "
                     "of `to` in the frame of `from`.")
        .def_property_readonly(
            "kind", [](const Edge& e) { return KindName(e.kind); }, "'odometry' or 'loop'")
        .def_readonly("from_", &Edge::from)
        .def_readonly("to", &Edge::to)
        .def_property_readonly("T_from_to",
                               [](const Edge& e) { return TransformToArray(e.T_from_to); })
        .def_property_readonly(
            "information", [](const Edge& e) { return MatrixToArray(e.information); },
            "(6, 6) information of the error (translation m, then quaternion x y z)")
        .def_readonly("loop", &Edge::loop, "loop edges: index into the loops given");
    py::class_<PoseGraph>(m, "PoseGraph",
                          "Poses T_world_sensor (the initial estimate) and the edges between them")
        .def_property_readonly(
            "poses", [](const PoseGraph& g) { return TransformsToArray(g.poses); },
            "(N, 4, 4) T_world_sensor, metres")
        .def_readonly("edges", &PoseGraph::edges);
    m.def(
        "build_pose_graph",
        [](const py::handle& odometry, const std::vector<LoopConstraint>& loops,
           const py::object& config, std::optional<std::vector<double>> path_m) {
            const std::vector<core::Transform> poses = TransformsFromArray(odometry, "odometry");
            const posegraph::PoseGraphConfig graph_config = PoseGraphConfigFrom(config);
            py::gil_scoped_release release;
            return posegraph::BuildPoseGraph(poses, loops, graph_config,
                                             std::move(path_m).value_or(std::vector<double>{}));
        },
        py::arg("odometry"), py::arg("loops"), py::arg("config") = py::none(),
        py::arg("path_m") = py::none(),
        "The graph of a trajectory: one pose per scan (odometry, (N, 4, 4) T_world_sensor), an "
        "odometry edge from each scan to the next, a loop edge from match to query per loop "
        "(informations from the config's posegraph section). path_m: per scan, the path "
        "travelled, which the odometry's drift grows with (None: the straight steps).");
}

void BindOptimisation(py::module_& m) {
    py::class_<LoopResult>(m, "LoopResult", "What the back end did with one loop edge")
        .def_readonly("loop", &LoopResult::loop, "index into the loops the graph was built from")
        .def_property_readonly(
            "verdict", [](const LoopResult& r) { return posegraph::ToString(r.verdict); },
            "'used', 'rejected_by_odometry', 'rejected_by_residual', 'rejected_by_consistency'")
        .def_readonly("path_m", &LoopResult::path_m)
        .def_readonly("odometry_translation_error_m", &LoopResult::odometry_translation_error_m)
        .def_readonly("odometry_rotation_error_deg", &LoopResult::odometry_rotation_error_deg)
        .def_readonly("gate_translation_m", &LoopResult::gate_translation_m)
        .def_readonly("gate_rotation_deg", &LoopResult::gate_rotation_deg)
        .def_readonly("initial_whitened_residual", &LoopResult::initial_whitened_residual)
        .def_readonly("whitened_residual", &LoopResult::whitened_residual)
        .def_readonly("support", &LoopResult::support);
    py::class_<OptimisationResult>(m, "OptimisationResult")
        .def_property_readonly(
            "poses", [](const OptimisationResult& r) { return TransformsToArray(r.poses); },
            "(N, 4, 4) optimised T_world_sensor, metres")
        .def_readonly("loops", &OptimisationResult::loops)
        .def_readonly("loops_used", &OptimisationResult::loops_used)
        .def_readonly("rejected_by_odometry", &OptimisationResult::rejected_by_odometry)
        .def_readonly("rejected_by_residual", &OptimisationResult::rejected_by_residual)
        .def_readonly("rejected_by_consistency", &OptimisationResult::rejected_by_consistency)
        .def_readonly("solves", &OptimisationResult::solves)
        .def_readonly("iterations", &OptimisationResult::iterations)
        .def_readonly("converged", &OptimisationResult::converged)
        .def_readonly("initial_cost", &OptimisationResult::initial_cost)
        .def_readonly("final_cost", &OptimisationResult::final_cost)
        .def_readonly("seconds", &OptimisationResult::seconds)
        .def_readonly("note", &OptimisationResult::note);
    m.def(
        "optimise_pose_graph",
        [](const PoseGraph& graph, const py::object& config) {
            const posegraph::PoseGraphConfig graph_config = PoseGraphConfigFrom(config);
            py::gil_scoped_release release;
            return posegraph::Optimise(graph, graph_config);
        },
        py::arg("graph"), py::arg("config") = py::none(),
        "Optimises the graph with Ceres (pose 0 fixed), keeping wrong loops out "
        "(docs/posegraph.md#robustness).");
}

void BindFiles(py::module_& m) {
    m.def(
        "write_g2o",
        [](const std::filesystem::path& file, const py::handle& poses,
           const std::vector<Edge>& edges, const std::vector<Edge>& commented_edges) {
            const std::vector<core::Transform> transforms = TransformsFromArray(poses, "poses");
            py::gil_scoped_release release;
            io::WriteG2o(file, transforms, edges, commented_edges);
        },
        py::arg("file"), py::arg("poses"), py::arg("edges"),
        py::arg("commented_edges") = std::vector<Edge>{},
        "Writes poses ((N, 4, 4) T_world_sensor) and edges in g2o's text format; "
        "commented_edges (rejected loops) after a '# rejected ' prefix.");
    m.def(
        "read_loops_csv",
        [](const std::filesystem::path& file, std::size_t scan_count) {
            std::vector<LoopConstraint> loops;
            for (const io::LoopRow& row : io::ReadLoopsCsv(file, scan_count))
                loops.push_back(row.loop);
            return loops;
        },
        py::arg("file"), py::arg("scan_count"),
        "The accepted loops of a loops.csv of `lidarloop detect` with verification.");
}

}  // namespace

void BindPosegraph(py::module_& m) {
    BindLoopConstraint(m);
    BindGraph(m);
    BindOptimisation(m);
    BindFiles(m);
}

}  // namespace lidarloop::python
