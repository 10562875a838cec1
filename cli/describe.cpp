#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "descriptor_options.hpp"
#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/descriptor_json.hpp"

namespace lidarloop::cli {

void AddDescribeCommand(CLI::App& app) {
    auto* command = app.add_subcommand("describe", "Print the descriptor of one scan as JSON");
    auto scan = std::make_shared<std::string>();
    auto options = std::make_shared<DescriptorOptions>();
    command
        ->add_option("SCAN", *scan,
                     "scan file (.bin .pcd .ply .xyz .txt .pts .3d) or BAG:TOPIC:INDEX")
        ->required();
    options->AddTo(*command);
    command->callback([scan, options] {
        const io::RunConfig config = options->Resolve();
        const core::Descriptor descriptor = app::DescribeScanFile(*scan, config.descriptor);
        std::cout << app::DescriptorJson(descriptor).dump() << "\n";
    });
}

}  // namespace lidarloop::cli
