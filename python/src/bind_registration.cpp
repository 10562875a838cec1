// Geometric verification of a scan pair (lidarloop::registration, app::VerifyClouds): what
// `lidarloop verify` computes, from NumPy arrays or scan files.
#include <cmath>
#include <string>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/verification.hpp"
#include "part2_helpers.hpp"

namespace lidarloop::python {
namespace {

using registration::PreparedScan;
using registration::Verification;

// The verification section of a run configuration (None, dict or YAML path): `lidarloop verify
// --config` reads the same section, so the defaults are the CLI's.
registration::VerificationConfig VerificationConfigFrom(const py::object& config) {
    registration::VerificationConfig verification = RunConfigFrom(config).detection.verification;
    verification.Validate();
    return verification;
}

// The `lidarloop verify` JSON of a verdict, as a dict (app::VerificationJson, the same keys).
py::dict VerdictDict(const Verification& verdict) {
    return py::module_::import("json").attr("loads")(app::VerificationJson(verdict).dump());
}

void BindVerification(py::module_& m) {
    py::class_<Verification>(m, "Verification",
                             "The verdict on one candidate pair: whether the query scan is "
                             "accepted as a revisit of the match scan, and the pose that says so.")
        .def_readonly("accepted", &Verification::accepted)
        .def_property_readonly(
            "reason", [](const Verification& v) { return registration::ToString(v.reason); },
            "why it was not accepted: 'none' (accepted), 'too_few_points', 'no_alignment', "
            "'not_converged', 'low_overlap', 'high_rmse', 'degenerate', 'ambiguous', 'too_far', "
            "'pruned', 'odometry_mismatch', 'not_needed', 'unlike_neighbours', 'unlike_revisit', "
            "'unlike_fits', 'unlike_motion'")
        .def_property_readonly(
            "T_match_query",
            [](const Verification& v) { return TransformToArray(v.T_match_query); },
            "(4, 4) float64: maps query-frame points into the match scan's frame, metres")
        .def_property_readonly(
            "overlap", [](const Verification& v) { return v.overlap.Min(); },
            "the smaller overlap fraction of the two ways, [0, 1]")
        .def_property_readonly(
            "overlap_query", [](const Verification& v) { return v.overlap.query_fraction; },
            "share of the query's structure points in view that lie on match surfaces")
        .def_property_readonly(
            "overlap_match", [](const Verification& v) { return v.overlap.match_fraction; },
            "the same, match on query")
        .def_property_readonly(
            "distinctive_overlap", [](const Verification& v) { return v.overlap.MinDistinctive(); },
            "the smaller overlap of the distinctive structure points (not on large planes)")
        .def_property_readonly(
            "distinctive_overlap_query",
            [](const Verification& v) { return v.overlap.query_distinctive_fraction; })
        .def_property_readonly(
            "distinctive_overlap_match",
            [](const Verification& v) { return v.overlap.match_distinctive_fraction; })
        .def_property_readonly("overlapping_points_query",
                               [](const Verification& v) { return v.overlap.query_overlapping; })
        .def_property_readonly("overlapping_points_match",
                               [](const Verification& v) { return v.overlap.match_overlapping; })
        .def_property_readonly(
            "rmse_m", [](const Verification& v) { return v.overlap.rmse_m; },
            "RMS plane distance of the overlapping points, both ways, metres")
        .def_property_readonly(
            "shifted_overlap",
            [](const Verification& v) -> py::object {
                if (std::isnan(v.shifted_overlap_ratio)) return py::none();
                return py::float_(v.shifted_overlap_ratio);
            },
            "the degeneracy test's overlap ratio after a shift along the weakest direction; "
            "None when not registered")
        .def_readonly("coarse_score", &Verification::coarse_score)
        .def_readonly("icp_iterations", &Verification::icp_iterations)
        .def_readonly("registered_hypotheses", &Verification::registered_hypotheses)
        .def_property_readonly("score", &Verification::score,
                               "confidence for ranking accepted loops: the smaller overlap")
        .def("to_dict", &VerdictDict,
             "The verdict as `lidarloop verify` prints it (without the files, points and times)")
        .def("__repr__", [](const Verification& v) {
            return "<Verification accepted=" + std::string(v.accepted ? "True" : "False") +
                   " reason=" + registration::ToString(v.reason) + ">";
        });
}

void BindPairVerification(py::module_& m) {
    py::class_<app::PairVerification>(m, "PairVerification",
                                      "What `lidarloop verify` computes for one pair of scans.")
        .def_readonly("verdict", &app::PairVerification::verdict)
        .def_readonly("query_points", &app::PairVerification::query_points,
                      "points of the query scan given")
        .def_readonly("match_points", &app::PairVerification::match_points)
        .def_readonly("prepare_ms", &app::PairVerification::prepare_ms,
                      "milliseconds to prepare both scans")
        .def_readonly("verify_ms", &app::PairVerification::verify_ms,
                      "milliseconds of coarse search, ICP and acceptance")
        .def(
            "to_dict",
            [](const app::PairVerification& p) {
                py::dict json = VerdictDict(p.verdict);
                json["points"] =
                    py::dict(py::arg("query") = p.query_points, py::arg("match") = p.match_points);
                json["time_ms"] = py::dict(py::arg("prepare_both") = p.prepare_ms,
                                           py::arg("verify") = p.verify_ms);
                return json;
            },
            "The JSON of `lidarloop verify` as a dict (without the file names)");
}

void BindPreparedScan(py::module_& m) {
    py::class_<PreparedScan>(m, "PreparedScan",
                             "A scan reduced for registration: voxel centroids with normals, "
                             "split into structure and ground (sensor frame, metres).")
        .def_readonly("input_points", &PreparedScan::input_points)
        .def_readonly("usable_points", &PreparedScan::usable_points,
                      "finite points within the range limits")
        .def_property_readonly(
            "structure_points",
            [](const PreparedScan& s) {
                return PointsToArray(s.structure ? s.structure->points() : core::PointCloud{});
            },
            "(N, 3) float32 structure points (normals far from vertical), metres")
        .def_property_readonly(
            "ground_points",
            [](const PreparedScan& s) {
                return PointsToArray(s.ground ? s.ground->points() : core::PointCloud{});
            },
            "(N, 3) float32 ground points, metres")
        .def_readonly("structure_roughness_m", &PreparedScan::structure_roughness_m)
        .def_property_readonly("memory_bytes", &PreparedScan::MemoryBytes);
}

void BindVerifyFunctions(py::module_& m) {
    m.def(
        "prepare_scan",
        [](const py::handle& points, const py::object& config, bool skip_non_finite) {
            const core::PointCloud cloud = PointsFromArray(points, skip_non_finite);
            const registration::VerificationConfig verification = VerificationConfigFrom(config);
            py::gil_scoped_release release;
            return registration::PrepareScan(cloud, verification.reduction);
        },
        py::arg("points"), py::arg("config") = py::none(), py::arg("skip_non_finite") = false,
        "Reduces a scan ((N, 3)/(N, 4) array, sensor frame, metres) for registration with the "
        "verification section of `config` (None, a dict or a YAML path).");
    m.def(
        "verify",
        [](const PreparedScan& query, const PreparedScan& match, const py::object& config) {
            const registration::VerificationConfig verification = VerificationConfigFrom(config);
            py::gil_scoped_release release;
            if (!query.structure) {
                Verification rejected;
                rejected.reason = registration::RejectReason::kTooFewPoints;
                return rejected;
            }
            const registration::CoarseQuery coarse(*query.structure, verification.coarse);
            return registration::Verify(query, coarse, match, verification);
        },
        py::arg("query"), py::arg("match"), py::arg("config") = py::none(),
        "Registers the prepared `query` to the prepared `match` without a prior pose and decides "
        "whether it is the same place (T_match_query maps query points into the match frame).");
    m.def(
        "verify_pair",
        [](const py::handle& query, const py::handle& match, const py::object& config,
           bool skip_non_finite) {
            const core::PointCloud query_cloud = PointsFromArray(query, skip_non_finite);
            const core::PointCloud match_cloud = PointsFromArray(match, skip_non_finite);
            const registration::VerificationConfig verification = VerificationConfigFrom(config);
            py::gil_scoped_release release;
            return app::VerifyClouds(query_cloud, match_cloud, verification);
        },
        py::arg("query"), py::arg("match"), py::arg("config") = py::none(),
        py::arg("skip_non_finite") = false,
        "`lidarloop verify` on two point arrays ((N, 3)/(N, 4), each in its sensor frame, "
        "metres): prepares both, verifies the query against the match, times both steps.");
    m.def(
        "verify_scan_files",
        [](const std::filesystem::path& query, const std::filesystem::path& match,
           const py::object& config) {
            const registration::VerificationConfig verification = VerificationConfigFrom(config);
            py::gil_scoped_release release;
            return app::VerifyScanFiles(query, match, verification);
        },
        py::arg("query_file"), py::arg("match_file"), py::arg("config") = py::none(),
        "`lidarloop verify QUERY MATCH`: reads two scan files (any format lidarloop reads) "
        "and verifies the first against the second.");
}

}  // namespace

void BindRegistration(py::module_& m) {
    BindVerification(m);
    BindPairVerification(m);
    BindPreparedScan(m);
    BindVerifyFunctions(m);
}

}  // namespace lidarloop::python
