#include "lidarloop/app/descriptor_json.hpp"

#include "lidarloop/core/scancontext/scancontext.hpp"

namespace lidarloop::app {
namespace {

nlohmann::json HistogramJson(const core::Histogram& histogram) {
    nlohmann::json json;
    json["method"] = core::ToString(histogram.projection);
    json["min"] = histogram.min_value;
    json["max"] = histogram.max_value;
    if (histogram.projection == core::Projection::kHeight) {
        json["up"] = {histogram.up.x(), histogram.up.y(), histogram.up.z()};
    }
    json["bins"] = histogram.mass;
    json["points_used"] = histogram.points_used;
    json["points_skipped"] = histogram.points_skipped;
    json["points_out_of_range"] = histogram.points_out_of_range;
    return json;
}

nlohmann::json NdtJson(const core::NdtDescriptorSet& set) {
    nlohmann::json json;
    json["method"] = "ndt";
    json["descriptors"] = nlohmann::json::array();
    for (const core::NdtDescriptor& f : set.descriptors) {
        nlohmann::json rows = nlohmann::json::array();
        for (int row = 0; row < f.rows; ++row) {
            const auto begin = f.counts.begin() + row * f.cols;
            rows.push_back(std::vector<float>(begin, begin + f.cols));
        }
        nlohmann::json rotation = nlohmann::json::array();
        for (int i = 0; i < 3; ++i) {
            rotation.push_back(
                {f.R_aligned_sensor(i, 0), f.R_aligned_sensor(i, 1), f.R_aligned_sensor(i, 2)});
        }
        json["descriptors"].push_back(
            {{"R_aligned_sensor", rotation}, {"cells", f.total}, {"F", rows}});
    }
    json["points_used"] = set.cell_stats.points_used;
    json["points_skipped"] = set.cell_stats.points_skipped;
    json["sparse_cells"] = set.cell_stats.sparse_cells;
    json["degenerate_cells"] = set.degenerate_cells;
    return json;
}

nlohmann::json ScanContextJson(const core::ScanContext& sc) {
    nlohmann::json rows = nlohmann::json::array();
    for (int ring = 0; ring < sc.rings; ++ring) {
        const auto begin = sc.bins.begin() + static_cast<std::ptrdiff_t>(ring) * sc.sectors;
        rows.push_back(std::vector<float>(begin, begin + sc.sectors));
    }
    nlohmann::json json;
    json["rings"] = sc.rings;
    json["sectors"] = sc.sectors;
    json["bins"] = rows;
    json["ring_key"] = sc.ring_key;
    json["points_used"] = sc.points_used;
    json["points_skipped"] = sc.points_skipped;
    json["points_out_of_range"] = sc.points_out_of_range;
    return json;
}

}  // namespace

nlohmann::json DescriptorJson(const core::Descriptor& descriptor) {
    // By the type the method keeps, so that a registered method built on either shows too.
    if (const auto* set = std::any_cast<core::NdtDescriptorSet>(&descriptor.value)) {
        nlohmann::json json = NdtJson(*set);
        json["method"] = core::ToString(descriptor.method);
        return json;
    }
    if (const auto* histogram = std::any_cast<core::Histogram>(&descriptor.value)) {
        nlohmann::json json = HistogramJson(*histogram);
        json["method"] = core::ToString(descriptor.method);
        return json;
    }
    if (const auto* sc = std::any_cast<core::ScanContext>(&descriptor.value)) {
        nlohmann::json json = ScanContextJson(*sc);
        json["method"] = core::ToString(descriptor.method);
        return json;
    }
    return {{"method", core::ToString(descriptor.method)}};
}

}  // namespace lidarloop::app
