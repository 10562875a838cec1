// The parts of rosbag.hpp that need no ROS library: names and scan references.
#include <algorithm>
#include <cctype>
#include <string>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/rosbag.hpp"

namespace lidarloop::io {

bool IsBagFile(const std::filesystem::path& file) {
    std::string extension = file.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension == ".bag";
}

std::optional<BagScanReference> ParseBagScanReference(const std::string& text) {
    const std::size_t index_colon = text.rfind(':');
    if (index_colon == std::string::npos || index_colon == 0) return std::nullopt;
    const std::size_t topic_colon = text.rfind(':', index_colon - 1);
    if (topic_colon == std::string::npos) return std::nullopt;
    BagScanReference reference;
    reference.bag = text.substr(0, topic_colon);
    if (!IsBagFile(reference.bag)) return std::nullopt;
    reference.topic = text.substr(topic_colon + 1, index_colon - topic_colon - 1);
    const std::string index = text.substr(index_colon + 1);
    const bool digits = !index.empty() && index.size() <= 18 &&
                        std::all_of(index.begin(), index.end(),
                                    [](unsigned char c) { return std::isdigit(c) != 0; });
    if (!digits) {
        throw ReadError(reference.bag, "scan reference " + core::Quoted(text) + ": INDEX " +
                                           core::Quoted(index) +
                                           " is no message number (BAG:TOPIC:INDEX, e.g. "
                                           "run.bag:/points:12)");
    }
    reference.index = std::stoull(index);
    return reference;
}

std::string ToString(const BagScanReference& reference) {
    return reference.bag.string() + ":" + reference.topic + ":" + std::to_string(reference.index);
}

core::PointCloud ReadBagScan(const BagScanReference& reference) {
    const auto scans = BagScans::Open(reference.bag, reference.topic);
    if (reference.index >= scans->size()) {
        throw ReadError(reference.bag, "topic " + core::Quoted(scans->topic()) + " has " +
                                           std::to_string(scans->size()) + " messages, no " +
                                           std::to_string(reference.index));
    }
    return scans->Load(reference.index);
}

}  // namespace lidarloop::io
