// Describing scans and comparing descriptors (lidarloop.descriptors, docs/python.md).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "conversions.hpp"
#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/descriptor_json.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/parameters.hpp"
#include "lidarloop/core/scancontext/scancontext.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"
#include "run_config.hpp"

namespace lidarloop::python {
namespace {

using core::Descriptor;

const core::Histogram& HistogramOf(const Descriptor& descriptor, const char* field) {
    const auto* histogram = std::any_cast<core::Histogram>(&descriptor.value);
    if (histogram == nullptr) {
        throw py::attribute_error("a " + core::ToString(descriptor.method) + " descriptor has no " +
                                  field + " (histograms have)");
    }
    return *histogram;
}

const core::NdtDescriptorSet& NdtOf(const Descriptor& descriptor, const char* field) {
    const auto* set = std::any_cast<core::NdtDescriptorSet>(&descriptor.value);
    if (set == nullptr) {
        throw py::attribute_error("a " + core::ToString(descriptor.method) + " descriptor has no " +
                                  field + " (NDT descriptor sets have)");
    }
    return *set;
}

// One rotation candidate F of an NDT set, as `lidarloop describe` prints it.
py::dict NdtDescriptorDict(const core::NdtDescriptor& f) {
    py::array_t<float> counts({f.rows, f.cols});
    std::copy(f.counts.begin(), f.counts.end(), counts.mutable_data());
    py::dict entry;
    entry["R_aligned_sensor"] = MatrixToArray(f.R_aligned_sensor);
    entry["cells"] = f.total;
    entry["F"] = counts;
    return entry;
}

const core::ScanContext* ScanContextOf(const Descriptor& descriptor) {
    return std::any_cast<core::ScanContext>(&descriptor.value);
}

// Points used: a histogram counts them in its buckets, an NDT set in its cells, a Scan Context
// in its bins.
std::size_t PointsUsed(const Descriptor& descriptor) {
    if (const auto* set = std::any_cast<core::NdtDescriptorSet>(&descriptor.value)) {
        return set->cell_stats.points_used;
    }
    if (const core::ScanContext* sc = ScanContextOf(descriptor)) return sc->points_used;
    return HistogramOf(descriptor, "points_used").points_used;
}

std::size_t PointsSkipped(const Descriptor& descriptor) {
    if (const auto* set = std::any_cast<core::NdtDescriptorSet>(&descriptor.value)) {
        return set->cell_stats.points_skipped;
    }
    if (const core::ScanContext* sc = ScanContextOf(descriptor)) return sc->points_skipped;
    return HistogramOf(descriptor, "points_skipped").points_skipped;
}

// The non-finite points a descriptor skipped, when its type counts them.
std::optional<std::size_t> SkippedPoints(const Descriptor& descriptor) {
    if (const auto* set = std::any_cast<core::NdtDescriptorSet>(&descriptor.value)) {
        return set->cell_stats.points_skipped;
    }
    if (const auto* histogram = std::any_cast<core::Histogram>(&descriptor.value)) {
        return histogram->points_skipped;
    }
    if (const core::ScanContext* sc = ScanContextOf(descriptor)) return sc->points_skipped;
    return std::nullopt;
}

// Describes points that C++ reads in place (no copy). Non-finite points are looked for only
// when the descriptor counted some, or cannot tell, so the common case reads the points once.
Descriptor DescribeView(core::PointsView points, const core::DescriptorConfig& config,
                        bool skip_non_finite) {
    py::gil_scoped_release release;
    Descriptor descriptor;
    try {
        descriptor = pipeline::ComputeDescriptorView(points, config);
    } catch (const core::EmptyInputError&) {
        // All points non-finite: say so rather than "nothing usable".
        const auto row = skip_non_finite ? std::nullopt : FirstNonFiniteRow(points);
        if (row) ThrowNonFiniteRow(*row);
        throw;
    }
    if (!skip_non_finite && SkippedPoints(descriptor).value_or(1) > 0) {
        if (const auto row = FirstNonFiniteRow(points)) ThrowNonFiniteRow(*row);
    }
    return descriptor;
}

// The keywords of a method's parameters (describe(scan, "ndt", cell_size_m=1.0)) as the keys of
// its section: read and checked by the YAML reader, like config={"ndt": {...}}.
void ApplyParameterKeywords(const py::kwargs& parameters, io::RunConfig& run) {
    if (parameters.empty()) return;
    const auto sections = pipeline::ParameterSectionsOf(run.descriptor);
    const pipeline::ParameterSection* own = pipeline::SectionOf(sections, run.descriptor.method);
    if (own == nullptr) {
        throw py::type_error("describe() got keywords " +
                             py::repr(parameters.attr("keys")()).cast<std::string>() +
                             ", but method '" + core::ToString(run.descriptor.method) +
                             "' has no parameters of its own (lidarloop.method_parameters)");
    }
    py::dict section;
    section[py::str(own->name)] = parameters;
    const std::string text = py::module_::import("json").attr("dumps")(section).cast<std::string>();
    io::ApplyConfigYaml(text, "keywords", run);
}

// One declared parameter as a dict: key, type, default, min, max (None: unbounded), unit, help.
class ParameterDicts final : public core::ParameterVisitor {
public:
    void Visit(const core::ParameterInfo& i, bool& value) override { Add(i, value, "bool"); }
    void Visit(const core::ParameterInfo& i, int& value) override { Add(i, value, "int"); }
    void Visit(const core::ParameterInfo& i, std::size_t& value) override { Add(i, value, "int"); }
    void Visit(const core::ParameterInfo& i, double& value) override { Add(i, value, "float"); }
    void Visit(const core::ParameterInfo& i, std::optional<double>& value) override {
        Add(i, value, "float | None");
    }
    void Visit(const core::ParameterInfo& i, std::vector<double>& value) override {
        Add(i, value, "list[float]");
    }
    void Visit(const core::ParameterInfo& i, std::string& value) override { Add(i, value, "str"); }
    py::list list;

private:
    template <typename T>
    void Add(const core::ParameterInfo& info, const T& value, const char* type) {
        py::dict d;
        d["key"] = std::string(info.key);
        d["type"] = type;
        d["default"] = py::cast(value);
        d["min"] = std::isfinite(info.min) ? py::cast(info.min) : py::none();
        d["max"] = std::isfinite(info.max) ? py::cast(info.max) : py::none();
        d["open"] = info.open;
        d["unit"] = std::string(info.unit);
        d["help"] = std::string(info.help);
        list.append(d);
    }
};

Descriptor Describe(const py::object& points, const std::optional<std::string>& method,
                    const py::object& config, const HistogramKeywords& keywords,
                    bool skip_non_finite, const py::kwargs& parameters) {
    io::RunConfig run = ResolveRunConfig(config, method, keywords);
    ApplyParameterKeywords(parameters, run);
    if (py::isinstance<py::str>(points) || py::hasattr(points, "__fspath__")) {
        const std::filesystem::path file = PathOf(points, "points");
        py::gil_scoped_release release;
        return app::DescribeScanFile(file, run.descriptor);
    }
    if (const auto view = ViewOfPoints(points)) {
        return DescribeView(*view, run.descriptor, skip_non_finite);
    }
    const core::PointCloud& cloud = ScratchPointsFromArray(points, skip_non_finite);
    py::gil_scoped_release release;
    return pipeline::ComputeDescriptor(cloud, run.descriptor);
}

void BindDescriptorClass(py::module_& m) {
    py::class_<Descriptor>(m, "Descriptor",
                           "The place descriptor of one scan, with the fields `lidarloop "
                           "describe` prints (to_dict() gives exactly its JSON). Made by "
                           "describe().")
        .def_property_readonly("method",
                               [](const Descriptor& d) { return core::ToString(d.method); })
        .def_property_readonly(
            "bins",
            [](const py::object& self) -> py::object {
                const auto& d = self.cast<const Descriptor&>();
                if (const core::ScanContext* sc = ScanContextOf(d)) {
                    py::array_t<float> bins({sc->rings, sc->sectors});
                    std::copy(sc->bins.begin(), sc->bins.end(), bins.mutable_data());
                    return bins;
                }
                return ViewOf(HistogramOf(d, "bins").mass, self);
            },
            "Histograms: the masses h_k of the b buckets, float64, summing to 1 (a read-only "
            "view of the C++ histogram, no copy). Scan Context: the (rings, sectors) float32 "
            "max heights, metres (a copy).")
        .def_property_readonly(
            "ring_key",
            [](const Descriptor& d) {
                const core::ScanContext* sc = ScanContextOf(d);
                if (sc == nullptr) {
                    throw py::attribute_error("a " + core::ToString(d.method) +
                                              " descriptor has no ring_key (Scan Contexts have)");
                }
                return sc->ring_key;
            },
            "Scan Context: per ring the share of its sectors that are occupied (a list).")
        .def_property_readonly(
            "min", [](const Descriptor& d) { return HistogramOf(d, "min").min_value; },
            "Histograms: v_min, metres (height above the ground plane, or range).")
        .def_property_readonly(
            "max", [](const Descriptor& d) { return HistogramOf(d, "max").max_value; },
            "Histograms: v_max, metres.")
        .def_property_readonly(
            "up",
            [](const Descriptor& d) {
                const core::Histogram& histogram = HistogramOf(d, "up");
                if (histogram.projection != core::Projection::kHeight) {
                    throw py::attribute_error("only a height histogram has an up vector");
                }
                return MatrixToArray(histogram.up);
            },
            "Height histograms: the unit up vector u of the projection, sensor frame, (3, 1).")
        .def_property_readonly("points_used", &PointsUsed,
                               "Points counted (histograms: in the buckets; NDT: in the cells).")
        .def_property_readonly("points_skipped", &PointsSkipped, "Non-finite points skipped.")
        .def_property_readonly(
            "points_out_of_range",
            [](const Descriptor& d) {
                if (const core::ScanContext* sc = ScanContextOf(d)) return sc->points_out_of_range;
                return HistogramOf(d, "points_out_of_range").points_out_of_range;
            },
            "Histograms: finite points outside [min, max] (clamped or dropped). Scan Context: "
            "finite points at a planar range >= max_range_m (dropped).")
        .def_property_readonly(
            "descriptors",
            [](const Descriptor& d) {
                py::list list;
                for (const auto& f : NdtOf(d, "descriptors").descriptors) {
                    list.append(NdtDescriptorDict(f));
                }
                return list;
            },
            "NDT: one dict per rotation candidate: 'F' (range intervals x classes float32 cell "
            "counts), 'cells' (their sum) and 'R_aligned_sensor' (3x3 rotation applied). Copies.")
        .def_property_readonly(
            "sparse_cells",
            [](const Descriptor& d) { return NdtOf(d, "sparse_cells").cell_stats.sparse_cells; },
            "NDT: cells with too few points to classify.")
        .def_property_readonly(
            "degenerate_cells",
            [](const Descriptor& d) { return NdtOf(d, "degenerate_cells").degenerate_cells; },
            "NDT: cells whose covariance was degenerate.")
        .def(
            "to_dict",
            [](const Descriptor& d) {
                const std::string json = app::DescriptorJson(d).dump();
                return py::module_::import("json").attr("loads")(json);
            },
            "Exactly the JSON object `lidarloop describe` prints, as plain Python values.")
        .def("distance", &pipeline::DescriptorDistance, py::arg("other"),
             "distance(self, other), see lidarloop.distance.")
        .def("__repr__", [](const Descriptor& d) {
            return "<lidarloop.Descriptor " + core::ToString(d.method) + ">";
        });
}

}  // namespace

void BindDescriptors(py::module_& m) {
    BindDescriptorClass(m);
    m.def(
        "describe",
        [](const py::object& points, const std::optional<std::string>& method,
           const py::object& config, std::optional<int> bins, std::optional<double> min,
           std::optional<double> max, std::optional<std::string> up,
           std::optional<double> sensor_height, std::optional<std::string> out_of_range,
           bool skip_non_finite, const py::kwargs& parameters) {
            const HistogramKeywords keywords{bins, min, max, up, sensor_height, out_of_range};
            return Describe(points, method, config, keywords, skip_non_finite, parameters);
        },
        py::arg("points"), py::arg("method") = py::none(), py::kw_only(),
        py::arg("config") = py::none(), py::arg("bins") = py::none(), py::arg("min") = py::none(),
        py::arg("max") = py::none(), py::arg("up") = py::none(),
        py::arg("sensor_height") = py::none(), py::arg("out_of_range") = py::none(),
        py::arg("skip_non_finite") = false,
        R"doc(The descriptor of one scan, as `lidarloop describe` computes it.

points: an (N, 3) or (N, 4) float32/float64 array (sensor frame, metres; a 4th column is
    ignored; any memory layout; copied once into the C++ layout), or a scan file path (read as
    `lidarloop describe SCAN` reads it).
method: 'height', 'range', 'ndt' or any registered method (lidarloop.method_names());
    default: the config's (height).
config: None, a dict nested like the YAML config ({'ndt': {'cell_size_m': 1.0}}), or a YAML
    file path; unknown keys raise lidarloop.ReadError.
bins, min, max (metres, of the projection in use), up ('fixed' | 'pca') and sensor_height
    (metres; both height only), out_of_range ('clamp' | 'drop'): as the short flags of
    `lidarloop describe`.
skip_non_finite: False raises lidarloop.NonFiniteError for a NaN/Inf point; True lets the
    descriptor skip and count them (points_skipped), as it does for files.
**parameters: the keys of the method's section by name (lidarloop.method_parameters(method)),
    e.g. describe(scan, 'scancontext', rings=30), describe(scan, 'ndt', cell_size_m=1.0),
    describe(scan, 'height', height_max_m=5.0); they override `config`'s section.
    Unknown keys and invalid values raise lidarloop.ReadError, as in a config dict.

Raises DtypeError, ShapeError, NonFiniteError, ConfigError, EmptyInputError (nothing usable),
ReadError (files). Releases the GIL while describing.)doc");
    m.def("distance", &pipeline::DescriptorDistance, py::arg("a"), py::arg("b"),
          "The method's distance between two descriptors of the same method and config: W "
          "(Roehling eq. 6) for histograms, sigma' (Magnusson eq. 9) for NDT, the column-shift "
          "distance (Kim eq. 5-6) for scancontext; 0 for equal descriptors, symmetric. "
          "lidarloop.ConfigError for mixed methods.");
    m.def(
        "scancontext_match",
        [](const Descriptor& query, const Descriptor& candidate) {
            const core::ScanContextMatch match = pipeline::MatchScanContexts(query, candidate);
            py::dict result;
            result["distance"] = match.distance;
            result["shift"] = match.shift;
            result["yaw_rad"] = match.yaw_rad;
            return result;
        },
        py::arg("query"), py::arg("candidate"),
        "Two scancontext descriptors: {'distance': d (Kim eq. 5-6), 'shift': n (query column j "
        "meets candidate column j + n), 'yaw_rad': the yaw of T_candidate_query that shift "
        "implies, in (-pi, pi]}. lidarloop.ConfigError for other descriptors.");
    m.def(
        "method_parameters",
        [](const std::string& method) {
            ParameterDicts dicts;
            const auto sections = pipeline::ParameterSectionsOf({});
            const auto* section = pipeline::SectionOf(sections, pipeline::ParseMethod(method));
            if (section != nullptr) section->visit(dicts);
            return dicts.list;
        },
        py::arg("method"),
        "The parameters of a method's section (histogram for height and range), as declared "
        "(docs/options.md): one dict per parameter with 'key', 'type', 'default', 'min', 'max' "
        "(None: unbounded), 'open' (whether min and max themselves are invalid), 'unit' and "
        "'help'; the keywords describe() takes for it. Names (up_vector, ...) are of type str.");
    m.def("method_names", &pipeline::MethodNames,
          "The registered descriptor methods: height, range, ndt, then any registered in C++.");
    m.def(
        "default_threshold",
        [](const std::string& method) {
            return pipeline::DefaultThreshold(pipeline::ParseMethod(method));
        },
        py::arg("method"), "The method's default decision threshold (tau or t_d).");
    m.def(
        "is_match",
        [](const std::string& method, double distance, double threshold) {
            return pipeline::IsMatch(pipeline::ParseMethod(method), distance, threshold);
        },
        py::arg("method"), py::arg("distance"), py::arg("threshold"),
        "Whether `distance` says 'same place' under `threshold`: W <= tau (histograms), "
        "sigma' < t_d (NDT).");
    m.def(
        "dump_config",
        [](const py::object& config) { return io::DumpConfigYaml(ResolveRunConfig(config, {})); },
        py::arg("config") = py::none(),
        "The effective configuration (defaults overridden by `config`, a dict or YAML path) as "
        "the YAML text `lidarloop dump-config` prints.");
}

}  // namespace lidarloop::python
