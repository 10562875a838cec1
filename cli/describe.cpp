#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "descriptor_options.hpp"

namespace lidarloop::cli {
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

}  // namespace

void AddDescribeCommand(CLI::App& app) {
    auto* command = app.add_subcommand("describe", "Print the descriptor of one scan as JSON");
    auto scan = std::make_shared<std::string>();
    auto options = std::make_shared<DescriptorOptions>();
    command->add_option("SCAN", *scan, "scan file (.bin .pcd .ply .xyz .txt .pts .3d)")
        ->required();
    options->AddTo(*command);
    command->callback([scan, options] {
        const io::RunConfig config = options->Resolve();
        std::cout << HistogramJson(HistogramOfFile(*scan, config)).dump() << "\n";
    });
}

}  // namespace lidarloop::cli
