#include <iostream>
#include <memory>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/app/run_options.hpp"
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
                      "print the descriptor methods' parameters as the Markdown table of "
                      "docs/cli.md instead (key, default, help, unit, range)");
    auto run_options = std::make_shared<bool>(false);
    command->add_flag("--markdown-run-options", *run_options,
                      "print the run options of detect, evaluate, optimise and bench as the "
                      "Markdown table of docs/cli.md instead");
    command->callback([config_file, markdown, run_options] {
        const io::RunConfig config =
            config_file->empty() ? io::RunConfig{} : io::LoadConfigYaml(*config_file);
        std::cout << (*run_options ? app::RunOptionsMarkdown()
                      : *markdown  ? io::DumpParametersMarkdown(config)
                                   : io::DumpConfigYaml(config));
    });
}

}  // namespace lidarloop::cli
