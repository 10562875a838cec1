#include <algorithm>
#include <iostream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "lidarloop/io/rosbag.hpp"

namespace lidarloop::cli {
namespace {

void PrintBagInfo(const std::string& file) {
    const std::vector<io::BagTopic> topics = io::ListBagTopics(file);
    std::size_t name_width = 5;
    std::size_t type_width = 4;
    for (const io::BagTopic& topic : topics) {
        name_width = std::max(name_width, topic.name.size());
        type_width = std::max(type_width, topic.type.size());
    }
    const auto row = [&](const std::string& name, const std::string& type,
                         const std::string& count) {
        std::cout << "  " << name << std::string(name_width - name.size() + 2, ' ') << type
                  << std::string(type_width - type.size() + 2, ' ') << count << "\n";
    };
    std::cout << file << ": " << topics.size() << (topics.size() == 1 ? " topic\n" : " topics\n");
    row("topic", "type", "messages");
    for (const io::BagTopic& topic : topics)
        row(topic.name, topic.type, std::to_string(topic.messages));
}

}  // namespace

void AddBagInfoCommand(CLI::App& app) {
    auto* command = app.add_subcommand(
        "bag-info", "List the topics of a ROS 1 bag with their message types and counts");
    auto file = std::make_shared<std::string>();
    command->add_option("BAG", *file, "a ROS 1 bag (.bag)")->required();
    command->callback([file] { PrintBagInfo(*file); });
}

}  // namespace lidarloop::cli
