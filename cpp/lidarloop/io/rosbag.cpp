// rosbag.hpp through Debian's rosbag_storage (ROS 1). Messages are read as bytes and decoded by
// ros_messages.hpp, so that no message package is compiled in and a bad message is our error,
// not a crash in generated code.
#include "lidarloop/io/rosbag.hpp"

#include <console_bridge/console.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <new>

#include <Eigen/Geometry>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/detail/bag_structure.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/ros_messages.hpp"

namespace lidarloop::io {
namespace fs = std::filesystem;
namespace {

// A message larger than this is damage (a 128-beam scan of 2048 columns is about 13 MB).
constexpr std::uint32_t kMaxMessageBytes = 256U << 20;

// rosbag_storage's message (a file offset, a record name) on one line of at most 200 characters.
std::string RosbagMessage(const char* what) {
    constexpr std::size_t kMaxChars = 200;
    std::string text;
    for (const char* c = what; *c != '\0' && text.size() < kMaxChars; ++c) {
        const auto code = static_cast<unsigned char>(*c);
        text += code < 0x20 || code == 0x7f ? ' ' : *c;
    }
    return text;
}

// rosbag_storage and ROS's header parser log what they then throw (or a message they skip) to
// stderr through console_bridge, several lines each; lidarloop reports what they throw as one
// error line instead, so their log is off from the first bag lidarloop opens.
void SilenceRosLog() {
    static std::once_flag once;
    std::call_once(once,
                   [] { console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE); });
}

// Runs `read`, turning what rosbag_storage, the decoder and allocation throw into ReadErrors
// naming `file` (and `context`, e.g. the topic and message).
template <typename Read>
auto Guarded(const fs::path& file, const std::string& context, Read&& read) {
    SilenceRosLog();
    const std::string prefix = context.empty() ? "" : context + ": ";
    try {
        return read();
    } catch (const ReadError&) {
        throw;
    } catch (const rosbag::BagUnindexedException&) {
        throw ReadError(file, prefix +
                                  "the bag has no index (a recording cut short?); `rosbag "
                                  "reindex` repairs it");
    } catch (const rosbag::BagException& e) {
        throw ReadError(file,
                        prefix + "not a readable ROS 1 bag (" + RosbagMessage(e.what()) + ")");
    } catch (const core::Error& e) {
        throw ReadError(file, prefix + e.what());
    } catch (const std::bad_alloc&) {
        throw ReadError(file, prefix + "a record claims more memory than there is (a corrupt bag)");
    } catch (const std::exception& e) {
        throw ReadError(file,
                        prefix + "not a readable ROS 1 bag (" + RosbagMessage(e.what()) + ")");
    }
}

std::string TopicContext(const std::string& topic) { return "topic " + core::Quoted(topic); }

// rosbag::MessageInstance::write's stream: the bytes go into a buffer of the message's size.
struct BufferStream {
    std::uint8_t* next;
    std::uint8_t* advance(std::uint32_t n) {
        std::uint8_t* at = next;
        next += n;
        return at;
    }
};

std::vector<std::uint8_t> MessageBytes(const rosbag::MessageInstance& message) {
    const std::uint32_t size = message.size();
    if (size > kMaxMessageBytes) {
        throw core::FormatError("a message of " + std::to_string(size) + " bytes, more than " +
                                std::to_string(kMaxMessageBytes >> 20) + " MiB (a corrupt bag)");
    }
    std::vector<std::uint8_t> bytes(size);
    BufferStream stream{bytes.data()};
    message.write(stream);
    return bytes;
}

struct TopicInfo {
    std::string type;
    std::string md5;
    std::size_t messages = 0;
};

std::map<std::string, TopicInfo> Topics(const rosbag::Bag& bag) {
    std::map<std::string, TopicInfo> topics;
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* connection : all.getConnections()) {
        TopicInfo& info = topics[connection->topic];
        info.type = connection->datatype;
        info.md5 = connection->md5sum;
    }
    for (auto& [name, info] : topics) {
        info.messages = rosbag::View(bag, rosbag::TopicQuery(name)).size();
    }
    return topics;
}

std::string TopicsOfType(const std::map<std::string, TopicInfo>& topics, const char* type) {
    std::string names;
    for (const auto& [name, info] : topics) {
        if (info.type == type) names += (names.empty() ? "" : ", ") + core::Quoted(name);
    }
    return names.empty() ? "none" : names;
}

void OpenBag(rosbag::Bag& bag, const fs::path& file) {
    std::error_code ec;
    if (!fs::exists(file, ec)) throw ReadError(file, "no such bag");
    if (fs::is_directory(file, ec)) throw ReadError(file, "is a folder, not a bag");
    Guarded(file, "", [&] {
        detail::CheckBagStructure(file);  // what rosbag_storage trusts
        bag.open(file.string(), rosbag::bagmode::Read);
    });
}

// The topic to read: `wanted`, or the only topic of `type` when `wanted` is empty, checked to
// hold messages of `type` (with its definition) and to have messages.
std::string ChooseTopic(const fs::path& file, const std::map<std::string, TopicInfo>& topics,
                        const std::string& wanted, const char* type, const char* md5,
                        const char* flag) {
    std::string topic = wanted;
    if (topic.empty()) {
        std::size_t count = 0;
        for (const auto& [name, info] : topics) {
            if (info.type == type) ++count, topic = name;
        }
        if (count != 1) {
            throw ReadError(file, "has " + std::to_string(count) + " " + type + " topics (" +
                                      TopicsOfType(topics, type) + "); name one with " + flag);
        }
    }
    const auto found = topics.find(topic);
    if (found == topics.end()) {
        throw ReadError(file, "has no topic " + core::Quoted(topic) + " (" + type +
                                  " topics: " + TopicsOfType(topics, type) + ")");
    }
    const TopicInfo& info = found->second;
    if (info.type != type) {
        throw ReadError(file, TopicContext(topic) + " holds " + core::Quoted(info.type) + ", not " +
                                  type + " (" + type + " topics: " + TopicsOfType(topics, type) +
                                  ")");
    }
    if (info.md5 != md5) {
        throw ReadError(file, TopicContext(topic) + " holds " + type +
                                  " of another definition (md5sum " + core::Quoted(info.md5) +
                                  ", expected " + md5 + ")");
    }
    if (info.messages == 0) throw ReadError(file, TopicContext(topic) + " has no messages");
    return topic;
}

}  // namespace

bool RosbagSupported() { return true; }

std::vector<BagTopic> ListBagTopics(const fs::path& file) {
    rosbag::Bag bag;
    OpenBag(bag, file);
    return Guarded(file, "", [&] {
        std::vector<BagTopic> list;
        for (const auto& [name, info] : Topics(bag))
            list.push_back({name, info.type, info.messages});
        return list;
    });
}

struct BagScans::Impl {
    fs::path file;
    std::string topic;
    rosbag::Bag bag;
    std::vector<rosbag::MessageInstance> messages;  // the index: chunk and offset of each
    std::vector<double> times_s;
    mutable std::mutex mutex;  // rosbag::Bag reads through one file handle and chunk buffer
};

BagScans::BagScans(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagScans::~BagScans() = default;

std::shared_ptr<const BagScans> BagScans::Open(const fs::path& file, const std::string& topic) {
    auto impl = std::make_unique<Impl>();
    impl->file = file;
    OpenBag(impl->bag, file);
    const auto topics = Guarded(file, "", [&] { return Topics(impl->bag); });
    impl->topic = ChooseTopic(file, topics, topic, kPointCloud2Type, kPointCloud2Md5, "--topic");
    Guarded(file, TopicContext(impl->topic), [&] {
        rosbag::View view(impl->bag, rosbag::TopicQuery(impl->topic));
        for (const rosbag::MessageInstance& message : view) {
            impl->times_s.push_back(ParseHeaderStamp(MessageBytes(message)));
            impl->messages.push_back(message);
        }
    });
    return std::shared_ptr<const BagScans>(new BagScans(std::move(impl)));
}

const fs::path& BagScans::file() const { return impl_->file; }
const std::string& BagScans::topic() const { return impl_->topic; }
std::size_t BagScans::size() const { return impl_->messages.size(); }
const std::vector<double>& BagScans::times_s() const { return impl_->times_s; }

core::PointCloud BagScans::Load(std::size_t index) const {
    const rosbag::MessageInstance& message = impl_->messages.at(index);
    return Guarded(impl_->file, TopicContext(impl_->topic) + " message " + std::to_string(index),
                   [&] {
                       std::vector<std::uint8_t> bytes;
                       {
                           const std::lock_guard<std::mutex> lock(impl_->mutex);
                           bytes = MessageBytes(message);
                       }
                       return DecodePointCloud2(ParsePointCloud2(bytes));
                   });
}

namespace {

// Sorted by time; of messages with one stamp the first in the bag is kept.
std::vector<core::StampedPose> ReadOdometryMessages(const rosbag::Bag& bag,
                                                    const std::string& topic) {
    std::vector<core::StampedPose> odometry;
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    std::size_t index = 0;
    for (const rosbag::MessageInstance& message : view) {
        try {
            odometry.push_back(ParseOdometry(MessageBytes(message)));
        } catch (const core::FormatError& e) {
            throw core::FormatError("message " + std::to_string(index) + ": " + e.what());
        }
        ++index;
    }
    std::stable_sort(odometry.begin(), odometry.end(),
                     [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
    odometry.erase(std::unique(odometry.begin(), odometry.end(),
                               [](const auto& a, const auto& b) { return a.time_s == b.time_s; }),
                   odometry.end());
    return odometry;
}

std::string Seconds(double t) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.6f s", t);
    return text;
}

core::Transform Interpolate(const core::StampedPose& a, const core::StampedPose& b, double t) {
    const double s = (t - a.time_s) / (b.time_s - a.time_s);
    const Eigen::Quaterniond qa(a.T_world_sensor.linear());
    const Eigen::Quaterniond qb(b.T_world_sensor.linear());
    core::Transform T = core::Transform::Identity();
    T.linear() = qa.slerp(s, qb).toRotationMatrix();
    T.translation() =
        (1.0 - s) * a.T_world_sensor.translation() + s * b.T_world_sensor.translation();
    return T;
}

std::vector<core::StampedPose> PosesAt(const std::vector<core::StampedPose>& odometry,
                                       const std::vector<double>& scan_times_s) {
    std::vector<core::StampedPose> poses;
    poses.reserve(scan_times_s.size());
    for (std::size_t i = 0; i < scan_times_s.size(); ++i) {
        const double t = scan_times_s[i];
        const auto after = std::lower_bound(
            odometry.begin(), odometry.end(), t,
            [](const core::StampedPose& pose, double time) { return pose.time_s < time; });
        if (after == odometry.end() || (after->time_s > t && after == odometry.begin())) {
            throw core::FormatError(
                "the odometry covers " + Seconds(odometry.front().time_s) + " to " +
                Seconds(odometry.back().time_s) + ", but scan " + std::to_string(i) + " is at " +
                Seconds(t) + " (the scans span " +
                Seconds(*std::min_element(scan_times_s.begin(), scan_times_s.end())) + " to " +
                Seconds(*std::max_element(scan_times_s.begin(), scan_times_s.end())) + ")");
        }
        core::StampedPose pose;
        pose.time_s = t;
        pose.T_world_sensor =
            after->time_s == t ? after->T_world_sensor : Interpolate(*(after - 1), *after, t);
        poses.push_back(pose);
    }
    return poses;
}

void CheckSteps(const std::vector<core::StampedPose>& poses, double max_step_m) {
    for (std::size_t i = 1; i < poses.size(); ++i) {
        const double step_m =
            (poses[i].T_world_sensor.translation() - poses[i - 1].T_world_sensor.translation())
                .norm();
        if (step_m > max_step_m) {
            throw core::FormatError("the odometry moves " + std::to_string(step_m) +
                                    " m from scan " + std::to_string(i - 1) + " to scan " +
                                    std::to_string(i) + ", more than " +
                                    std::to_string(max_step_m) + " m (a jump or a reset)");
        }
    }
}

}  // namespace

std::vector<core::StampedPose> ReadBagOdometry(const fs::path& file, const std::string& topic,
                                               const std::vector<double>& scan_times_s,
                                               double max_step_m) {
    rosbag::Bag bag;
    OpenBag(bag, file);
    const auto topics = Guarded(file, "", [&] { return Topics(bag); });
    const std::string chosen =
        ChooseTopic(file, topics, topic, kOdometryType, kOdometryMd5, "--odometry-topic");
    return Guarded(file, "odometry " + TopicContext(chosen), [&] {
        const std::vector<core::StampedPose> poses =
            PosesAt(ReadOdometryMessages(bag, chosen), scan_times_s);
        CheckSteps(poses, max_step_m);
        return poses;
    });
}

}  // namespace lidarloop::io
