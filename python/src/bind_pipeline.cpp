// The descriptor database, its nearest-neighbour index and the online loop detector
// (lidarloop.pipeline, docs/python.md).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/verification_run.hpp"
#include "lidarloop/io/database_file.hpp"
#include "lidarloop/io/prepared_scans_file.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "run_config.hpp"

namespace lidarloop::python {
namespace {

using pipeline::DescriptorDatabase;
using pipeline::LoopDetector;
using pipeline::LoopQuery;
using pipeline::Neighbor;
using std::filesystem::path;

// An index that keeps its database alive (the C++ index refers to the database's store).
struct Index {
    std::unique_ptr<pipeline::NeighborIndex> index;
    const DescriptorDatabase* database = nullptr;
};

// A boolean mask over the database's scans as the index's eligibility test; empty: every scan.
std::function<bool(std::size_t)> EligibleOf(const py::object& mask, std::size_t size,
                                            std::vector<std::uint8_t>& storage) {
    if (mask.is_none()) return {};
    const auto array = py::array_t<bool, py::array::forcecast>::ensure(mask);
    if (!array || array.ndim() != 1 || static_cast<std::size_t>(array.shape(0)) != size) {
        throw ShapeError("eligible must be a boolean array with one entry per stored scan (" +
                         std::to_string(size) + ")");
    }
    storage.assign(array.data(), array.data() + size);
    return [&storage](std::size_t id) { return storage[id] != 0; };
}

py::array_t<double> DistancesTo(const DescriptorDatabase& database,
                                const core::Descriptor& descriptor) {
    py::array_t<double> distances(static_cast<py::ssize_t>(database.size()));
    double* out = distances.mutable_data();
    py::gil_scoped_release release;
    const std::unique_ptr<pipeline::PreparedQuery> query = database.Prepare(descriptor);
    for (std::size_t j = 0; j < database.size(); ++j) out[j] = database.Distance(*query, j);
    return distances;
}

void BindNeighbor(py::module_& m) {
    py::class_<Neighbor>(m, "Neighbor", "A stored scan and its descriptor distance to a query.")
        .def_readonly("index", &Neighbor::index, "The stored scan's index.")
        .def_readonly("distance", &Neighbor::distance, "The method's distance (W, sigma', ...).")
        .def("__repr__", [](const Neighbor& n) {
            return "Neighbor(index=" + std::to_string(n.index) +
                   ", distance=" + py::repr(py::float_(n.distance)).cast<std::string>() + ")";
        });
}

void BindDatabase(py::module_& m) {
    py::class_<DescriptorDatabase>(
        m, "DescriptorDatabase",
        "The descriptors of a sequence of scans under one method and config, in scan order, "
        "with their times; kept in the form that compares fastest. Not thread-safe for writing.")
        .def(py::init([](const py::object& config, const std::optional<std::string>& method) {
                 return DescriptorDatabase(ResolveRunConfig(config, method).descriptor);
             }),
             py::arg("config") = py::none(), py::arg("method") = py::none(),
             "An empty database for descriptors made under `config` (None, dict or YAML path) "
             "and `method`. Add descriptors made with the same config (describe(..., "
             "config=..., method=...)).")
        .def("__len__", &DescriptorDatabase::size)
        .def_property_readonly(
            "method", [](const DescriptorDatabase& d) { return core::ToString(d.method()); })
        .def(
            "add",
            [](DescriptorDatabase& d, const core::Descriptor& descriptor,
               std::optional<double> time_s) {
                return d.Add(descriptor, time_s.value_or(static_cast<double>(d.size())));
            },
            py::arg("descriptor"), py::arg("time_s") = py::none(),
            "Appends the next scan's descriptor (recorded at time_s seconds; default: its "
            "index) and returns its index. lidarloop.ConfigError for another method.")
        .def(
            "add_missing",
            [](DescriptorDatabase& d, std::optional<double> time_s) {
                return d.AddMissing(time_s.value_or(static_cast<double>(d.size())));
            },
            py::arg("time_s") = py::none(),
            "Appends a placeholder for a scan that could not be described (never matches).")
        .def(
            "is_valid",
            [](const DescriptorDatabase& d, std::size_t i) { return d.IsValid(CheckedScan(d, i)); },
            py::arg("i"))
        .def_property_readonly(
            "times_s", [](const DescriptorDatabase& d) { return ArrayOf(d.times_s()); },
            "The scans' times, seconds (a copy: a view would dangle once the database grows).")
        .def(
            "distance",
            [](const DescriptorDatabase& d, std::size_t i, std::size_t j) {
                return d.Distance(CheckedScan(d, i), CheckedScan(d, j));
            },
            py::arg("i"), py::arg("j"),
            "The distance between stored scans i and j; inf when one is a placeholder.")
        .def("distances", &DistancesTo, py::arg("descriptor"),
             "The distances from `descriptor` (not stored) to every stored scan, float64 (inf "
             "for placeholders). Releases the GIL.")
        .def(
            "save",
            [](const DescriptorDatabase& d, const path& file) {
                py::gil_scoped_release release;
                io::SaveDatabase(file, d);
            },
            py::arg("file"),
            "Writes the database as a .lldb file (what `lidarloop detect` saves); "
            "lidarloop.WriteError when it cannot.")
        .def_static(
            "load",
            [](const path& file) {
                py::gil_scoped_release release;
                return io::LoadDatabase(file);
            },
            py::arg("file"),
            "Reads a .lldb file; lidarloop.ReadError naming what is wrong with it.")
        .def(
            "index",
            [](const DescriptorDatabase& d) -> std::optional<Index> {
                std::unique_ptr<pipeline::NeighborIndex> index = d.store().MakeIndex();
                if (!index) return std::nullopt;
                return Index{std::move(index), &d};
            },
            py::keep_alive<0, 1>(),
            "A nearest-neighbour index over this database (None when the method has none, e.g. "
            "NDT, or scancontext with ring_key_candidates 0); exact except scancontext's "
            "ring-key search. It refers to the database: scans added later are searched only "
            "after insert().");
}

void BindIndex(py::module_& m) {
    py::class_<Index>(m, "NeighborIndex",
                      "Exact k-nearest-neighbour search over a database's valid scans; gives "
                      "exactly what comparing every scan gives. Made by "
                      "DescriptorDatabase.index().")
        .def(
            "insert",
            [](Index& index, std::size_t id) {
                index.index->Insert(CheckedScan(*index.database, id));
            },
            py::arg("id"), "Indexes stored scan `id` (each once).")
        .def(
            "insert_all",
            [](Index& index) {
                py::gil_scoped_release release;
                index.index->InsertAll({});
            },
            "Indexes every stored scan not yet indexed.")
        .def(
            "search",
            [](const Index& index, const core::Descriptor& descriptor, std::size_t k,
               const py::object& eligible) {
                std::vector<std::uint8_t> mask;
                const auto include = EligibleOf(eligible, index.database->size(), mask);
                py::gil_scoped_release release;
                const auto query = index.database->Prepare(descriptor);
                return index.index->Search(*query, k, include);
            },
            py::arg("descriptor"), py::arg("k"), py::arg("eligible") = py::none(),
            "The k indexed scans nearest to `descriptor`, by (distance, index); `eligible` (a "
            "boolean array, one entry per stored scan) restricts them. Releases the GIL.");
}

void BindLoopQuery(py::module_& m) {
    py::class_<LoopQuery>(m, "LoopQuery", "What the detector says about one query scan.")
        .def_readonly("query", &LoopQuery::query, "The query scan's index.")
        .def_readonly("candidates", &LoopQuery::candidates,
                      "Up to top_k eligible stored scans (Neighbor), nearest first; when "
                      "verifying, in the order registration takes them (nearest views by "
                      "the odometry, else most alike layouts, first).")
        .def_readonly("second_ratio", &LoopQuery::second_ratio,
                      "The best match's distance over the best candidate's outside the gap "
                      "around it (near 0: distinctive; NaN: no such candidate).")
        .def_readonly("accepted", &LoopQuery::accepted,
                      "Without verification: the best match passes the threshold; with: some "
                      "candidate passed verification.")
        .def_readonly("verifications", &LoopQuery::verifications,
                      "Geometric verification of each candidate, in their order (empty when "
                      "not verified).")
        .def_property_readonly("verified", &LoopQuery::verified,
                               "Whether the candidates were verified.")
        .def_property_readonly("loop", &LoopQuery::loop,
                               "The index in `candidates` of the loop, or None.")
        .def_property_readonly(
            "match",
            [](const LoopQuery& q) -> std::optional<std::size_t> {
                const auto loop = q.loop();
                if (!loop) return std::nullopt;
                return q.candidates[*loop].index;
            },
            "The stored scan the query closes a loop with, or None.")
        .def("__repr__", [](const LoopQuery& q) {
            return "<lidarloop.LoopQuery " + std::to_string(q.query) + ": " +
                   std::to_string(q.candidates.size()) + " candidates, " +
                   (q.accepted ? "accepted" : "not accepted") + ">";
        });
}

pipeline::DetectorConfig DetectionOf(const io::RunConfig& run, std::optional<int> top_k,
                                     std::optional<double> min_gap,
                                     const std::optional<std::string>& min_gap_unit,
                                     std::optional<double> min_path_m,
                                     std::optional<double> threshold, std::optional<bool> verify,
                                     std::optional<bool> stop_at_first_loop) {
    pipeline::DetectorConfig detection = run.detection;
    if (top_k) detection.top_k = *top_k;
    if (min_gap) detection.min_gap.value = *min_gap;
    if (min_gap_unit) detection.min_gap.unit = core::ParseMinGapUnit(*min_gap_unit);
    if (min_path_m) detection.min_path_m = *min_path_m;
    if (threshold) detection.threshold = *threshold;
    if (verify) detection.verify = *verify;
    if (stop_at_first_loop) detection.stop_at_first_loop = *stop_at_first_loop;
    detection.Validate();
    return detection;
}

// The map's prepared scans when the detector verifies: as `lidarloop detect --map` checks them.
std::vector<registration::PreparedScan> MapScans(app::LoadedMap& map,
                                                 const pipeline::DetectorConfig& detection) {
    if (!detection.verify) return {};
    if (!map.scans || map.scans->reduction != detection.verification.reduction ||
        map.scans->scans.size() != map.database.size()) {
        throw core::ConfigError("the map " + map.file.string() +
                                " has no matching prepared scans (" +
                                io::PreparedScansPathOf(map.file).string() +
                                ") to verify against; load it with "
                                "verify=False");
    }
    return std::move(map.scans->scans);
}

std::unique_ptr<LoopDetector> LoadDetector(const path& file, std::optional<bool> verify) {
    app::LoadedMap map = app::LoadMap(file);
    if (verify) map.detection.verify = *verify;
    std::vector<registration::PreparedScan> scans = MapScans(map, map.detection);
    auto detector =
        std::make_unique<LoopDetector>(std::move(map.database), map.detection, std::move(scans));
    // The map keeps no pose graph section: the default gate, as a new detector's.
    detector->SetOdometryGate(app::OdometryGateOf(posegraph::PoseGraphConfig{}));
    return detector;
}

void BindDetector(py::module_& m) {
    py::class_<LoopDetector, std::unique_ptr<LoopDetector>>(
        m, "LoopDetector",
        "Online loop detection: each scan given to process() is compared with the stored scans "
        "more than min_gap older (and its candidates verified when verify is on), then "
        "stored. process() is not thread-safe; query() may run concurrently.")
        .def(py::init([](const py::object& config, const std::optional<std::string>& method,
                         std::optional<int> top_k, std::optional<double> min_gap,
                         const std::optional<std::string>& min_gap_unit,
                         std::optional<double> min_path_m, std::optional<double> threshold,
                         std::optional<bool> verify, std::optional<bool> stop_at_first_loop) {
                 const io::RunConfig run = ResolveRunConfig(config, method);
                 auto detector = std::make_unique<LoopDetector>(
                     run.descriptor, DetectionOf(run, top_k, min_gap, min_gap_unit, min_path_m,
                                                 threshold, verify, stop_at_first_loop));
                 detector->SetOdometryGate(app::OdometryGateOf(run.posegraph));
                 return detector;
             }),
             py::arg("config") = py::none(), py::arg("method") = py::none(), py::kw_only(),
             py::arg("top_k") = py::none(), py::arg("min_gap") = py::none(),
             py::arg("min_gap_unit") = py::none(), py::arg("min_path_m") = py::none(),
             py::arg("threshold") = py::none(), py::arg("verify") = py::none(),
             py::arg("stop_at_first_loop") = py::none(),
             "config: None, dict or YAML path (descriptor, `detection` and `posegraph` keys); "
             "method; top_k, min_gap (in the config's unit, scans by default), min_gap_unit "
             "('scans', 'seconds', 'metres': needs the odometry), min_path_m (default 50: and "
             "more than this much path back when process is given the odometry; 0: off), "
             "threshold, verify, "
             "stop_at_first_loop (default True: register the candidates in rank order up to "
             "the first loop; False: every candidate) override detection.*. Loops the odometry "
             "contradicts (process's odometry) are rejected by the pose graph's gate "
             "(posegraph.robust).")
        .def(
            "process",
            [](LoopDetector& detector, const py::object& points, std::optional<double> time_s,
               bool skip_non_finite, const py::object& odometry) {
                const core::PointCloud& cloud = ScratchPointsFromArray(points, skip_non_finite);
                const double t = time_s.value_or(static_cast<double>(detector.database().size()));
                std::optional<core::Transform> T_odom_sensor;
                if (!odometry.is_none()) T_odom_sensor = TransformFromArray(odometry, "odometry");
                py::gil_scoped_release release;
                return detector.Process(cloud, t, T_odom_sensor);
            },
            py::arg("points"), py::arg("time_s") = py::none(), py::arg("skip_non_finite") = false,
            py::arg("odometry") = py::none(),
            "Describes an (N, 3)/(N, 4) scan (sensor frame, metres; copied once), finds its "
            "candidates among the stored scans (verifying them when verify is on), stores it "
            "and returns the LoopQuery. time_s: seconds, default its index. odometry: the "
            "scan's (4, 4) pose T_odom_sensor by the odometry, for every scan or none: a gap in "
            "metres of path, and verified loops it contradicts rejected (odometry_mismatch). "
            "Releases the GIL.")
        .def(
            "process_descriptor",
            [](LoopDetector& detector, const core::Descriptor& descriptor,
               std::optional<double> time_s) {
                const double t = time_s.value_or(static_cast<double>(detector.database().size()));
                py::gil_scoped_release release;
                return detector.Process(descriptor, t);
            },
            py::arg("descriptor"), py::arg("time_s") = py::none(),
            "process() for a scan already described; it is neither verified nor verifiable.")
        .def(
            "query",
            [](const LoopDetector& detector, const core::Descriptor& descriptor) {
                py::gil_scoped_release release;
                return detector.Query(descriptor);
            },
            py::arg("descriptor"),
            "Localisation: every stored scan is a candidate and the query is not stored (not "
            "verified).")
        .def_property_readonly(
            "database", [](const LoopDetector& d) { return d.database(); },
            "A copy of the stored scans' descriptors: changing it does not change the detector, "
            "whose database grows only by process().")
        .def("__len__", [](const LoopDetector& d) { return d.database().size(); })
        .def_property_readonly("threshold", &LoopDetector::threshold,
                               "The decision threshold applied.")
        .def_property_readonly("top_k",
                               [](const LoopDetector& d) { return d.detector_config().top_k; })
        .def_property_readonly("verify",
                               [](const LoopDetector& d) { return d.detector_config().verify; })
        .def_property_readonly(
            "stop_at_first_loop",
            [](const LoopDetector& d) { return d.detector_config().stop_at_first_loop; })
        .def(
            "save",
            [](const LoopDetector& detector, const path& file) {
                py::gil_scoped_release release;
                app::SaveDetectorMap(detector, file);
            },
            py::arg("file"),
            "Writes the stored scans as a map: FILE (.lldb, with the detection config) and, when "
            "scans were kept for verification, FILE with the extension .scans (else an earlier "
            "map's prepared scans there are removed, which would be taken for this map's) -- "
            "what `lidarloop detect` writes and `lidarloop detect --map` reads.")
        .def_static(
            "load",
            [](const path& file, std::optional<bool> verify) {
                py::gil_scoped_release release;
                return LoadDetector(file, verify);
            },
            py::arg("file"), py::arg("verify") = py::none(),
            "A detector continuing from a saved map (its .lldb and .scans); verify overrides "
            "the saved detection.verify. lidarloop.ReadError for a damaged file, ConfigError "
            "when verifying without the map's prepared scans.");
}

}  // namespace

void BindPipeline(py::module_& m) {
    BindNeighbor(m);
    BindDatabase(m);
    BindIndex(m);
    BindLoopQuery(m);
    BindDetector(m);
}

}  // namespace lidarloop::python
