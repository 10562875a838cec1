#include <cstdio>
#include <memory>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "descriptor_options.hpp"
#include "lidarloop/app/describe_run.hpp"

namespace lidarloop::cli {

void AddDistanceCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "distance",
        "Print the distance between two scans: W (Roehling eq. 6) or sigma' (Magnusson eq. 9)");
    auto scans = std::make_shared<std::vector<std::string>>();
    auto options = std::make_shared<DescriptorOptions>();
    command->add_option("SCAN_A SCAN_B", *scans, "two scan files (or BAG:TOPIC:INDEX)")
        ->required()
        ->expected(2);
    options->AddTo(*command);
    command->callback([scans, options] {
        const io::RunConfig config = options->Resolve();
        const core::Descriptor a = app::DescribeScanFile((*scans)[0], config.descriptor);
        const core::Descriptor b = app::DescribeScanFile((*scans)[1], config.descriptor);
        // %.9g keeps enough digits to compare against thresholds near 1e-3.
        std::printf("%.9g\n", pipeline::DescriptorDistance(a, b));
    });
}

}  // namespace lidarloop::cli
