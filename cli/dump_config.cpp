#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/io/config_yaml.hpp"

namespace lidarloop::cli {

void AddDumpConfigCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "dump-config", "Print the configuration as YAML (the defaults, or --config applied)");
    auto config_file = std::make_shared<std::string>();
    command->add_option("--config", *config_file, "YAML file to apply before printing")
        ->check(CLI::ExistingFile);
    auto markdown = std::make_shared<bool>(false);
    command->add_flag("--markdown", *markdown,
                      "print the registered methods' parameters as the Markdown table of "
                      "docs/cli.md instead (key, default, help, unit, range)");
    command->callback([config_file, markdown] {
        const io::RunConfig config =
            config_file->empty() ? io::RunConfig{} : io::LoadConfigYaml(*config_file);
        std::cout << (*markdown ? io::DumpParametersMarkdown(config) : io::DumpConfigYaml(config));
    });
}

}  // namespace lidarloop::cli
