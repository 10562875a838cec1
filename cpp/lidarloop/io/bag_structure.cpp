// The ROS 1 bag format 2.0 (wiki.ros.org/Bags/Format/2.0): "#ROSBAG V2.0\n", then records of
// <uint32 header_len><header><uint32 data_len><data>, a header being fields <uint32 len>name=value.
#include "lidarloop/io/detail/bag_structure.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io::detail {
namespace {

constexpr char kVersionLine[] = "#ROSBAG V2.0\n";
constexpr std::uint64_t kVersionBytes = sizeof(kVersionLine) - 1;
// rosbag_storage allocates a compressed chunk's declared size before decompressing it. Writers
// close a chunk at 768 kB by default, after one message at most: 128 MiB is ten times the
// largest LiDAR scan message (Ouster 128 x 2048 points), and under libFuzzer's 512 MiB limit.
constexpr std::uint32_t kMaxChunkBytes = 1U << 27;
constexpr std::uint32_t kMaxHeaderBytes = 1U << 20;  // record headers hold a few short fields
constexpr std::uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpIndex = 0x04, kOpChunk = 0x05,
                       kOpChunkInfo = 0x06, kOpConnection = 0x07;

class BagFile {
public:
    explicit BagFile(const std::filesystem::path& file)
        : file_(file), in_(file, std::ios::binary), size_(std::filesystem::file_size(file)) {
        if (!in_) throw ReadError(file, "cannot open the bag");
    }
    std::uint64_t size() const { return size_; }
    [[noreturn]] void Fail(std::uint64_t at, const std::string& problem) const {
        throw ReadError(file_, "damaged bag at byte " + std::to_string(at) + ": " + problem);
    }
    std::string Read(std::uint64_t at, std::uint64_t n, const char* what) {
        if (at > size_ || n > size_ - at) {
            Fail(at, std::string(what) + " of " + std::to_string(n) + " bytes runs past the end (" +
                         std::to_string(size_) + " bytes; a bag cut short?)");
        }
        std::string bytes(n, '\0');
        in_.seekg(static_cast<std::streamoff>(at));
        in_.read(bytes.data(), static_cast<std::streamsize>(n));
        if (!in_) Fail(at, std::string("cannot read ") + what);
        return bytes;
    }
    std::uint32_t U32(std::uint64_t at, const char* what) {
        const std::string bytes = Read(at, 4, what);
        std::uint32_t value;
        std::memcpy(&value, bytes.data(), 4);
        return value;
    }

private:
    std::filesystem::path file_;
    std::ifstream in_;
    std::uint64_t size_;
};

template <typename T>
T FieldValue(const std::string& value) {
    T result{};
    std::memcpy(&result, value.data(), std::min(sizeof(T), value.size()));
    return result;
}

struct Record {
    std::uint64_t at = 0;
    std::map<std::string, std::string> fields;
    std::uint64_t data_at = 0;
    std::uint32_t data_len = 0;
    std::uint64_t end = 0;
    std::uint8_t op = 0;
};

// The fields <uint32 len>name=value of `header` (a record's header, or a connection record's
// data, which rosbag_storage parses the same way without checking the lengths).
std::map<std::string, std::string> HeaderFields(BagFile& bag, std::uint64_t at,
                                                const std::string& header) {
    std::map<std::string, std::string> fields;
    for (std::size_t pos = 0; pos < header.size();) {
        if (header.size() - pos < 4) bag.Fail(at, "a header field's length is cut");
        std::uint32_t len;
        std::memcpy(&len, header.data() + pos, 4);
        pos += 4;
        if (len > header.size() - pos) bag.Fail(at, "a header field runs past its header");
        const std::string field = header.substr(pos, len);
        pos += len;
        const std::size_t equals = field.find('=');
        if (equals == std::string::npos) bag.Fail(at, "a header field without '='");
        fields[field.substr(0, equals)] = field.substr(equals + 1);
    }
    return fields;
}

Record ReadRecord(BagFile& bag, std::uint64_t at) {
    Record record;
    record.at = at;
    const std::uint32_t header_len = bag.U32(at, "a record's header length");
    if (header_len > kMaxHeaderBytes)
        bag.Fail(at, "a record header of " + std::to_string(header_len) + " bytes");
    record.fields = HeaderFields(bag, at, bag.Read(at + 4, header_len, "a record header"));
    const auto op = record.fields.find("op");
    if (op == record.fields.end() || op->second.size() != 1) bag.Fail(at, "a record without op");
    record.op = static_cast<std::uint8_t>(op->second[0]);
    record.data_len = bag.U32(at + 4 + header_len, "a record's data length");
    record.data_at = at + 8 + header_len;
    if (record.data_len > bag.size() - record.data_at) {
        bag.Fail(at,
                 "a record's data of " + std::to_string(record.data_len) +
                     " bytes runs past the end (a bag cut short? `rosbag reindex` repairs one)");
    }
    record.end = record.data_at + record.data_len;
    return record;
}

std::uint64_t Field64(BagFile& bag, const Record& record, const char* name) {
    const auto found = record.fields.find(name);
    if (found == record.fields.end() || found->second.size() != 8)
        bag.Fail(record.at, std::string("a record without its 8-byte ") + name);
    return FieldValue<std::uint64_t>(found->second);
}

std::uint32_t Field32(BagFile& bag, const Record& record, const char* name) {
    const auto found = record.fields.find(name);
    if (found == record.fields.end() || found->second.size() != 4)
        bag.Fail(record.at, std::string("a record without its 4-byte ") + name);
    return FieldValue<std::uint32_t>(found->second);
}

struct Chunk {
    std::uint64_t data_at = 0;
    std::uint32_t size = 0;  // uncompressed
    bool compressed = false;
};

Chunk CheckChunk(BagFile& bag, const Record& record) {
    const auto compression = record.fields.find("compression");
    if (compression == record.fields.end()) bag.Fail(record.at, "a chunk without compression");
    const std::string& name = compression->second;
    if (name != "none" && name != "bz2" && name != "lz4")
        bag.Fail(record.at, "a chunk of unknown compression " + core::Quoted(name));
    Chunk chunk{record.data_at, Field32(bag, record, "size"), name != "none"};
    if (chunk.size > kMaxChunkBytes) {
        bag.Fail(record.at,
                 "a chunk claims " + std::to_string(chunk.size) + " bytes, more than 128 MiB");
    }
    if (!chunk.compressed && chunk.size != record.data_len)
        bag.Fail(record.at, "an uncompressed chunk whose size is not its data length");
    return chunk;
}

// Index data of version 1: count entries of <uint64 time><uint32 offset> into the chunk before.
void CheckIndex(BagFile& bag, const Record& record, const Chunk* chunk) {
    if (chunk == nullptr) bag.Fail(record.at, "an index record before any chunk");
    if (Field32(bag, record, "ver") != 1) bag.Fail(record.at, "an index record of unknown version");
    const std::uint32_t count = Field32(bag, record, "count");
    if (count > chunk->size / 8)
        bag.Fail(record.at, "an index of more messages than its chunk holds");
    if (std::uint64_t{count} * 12 != record.data_len)
        bag.Fail(record.at, "an index record whose count does not match its data");
    const std::string entries = bag.Read(record.data_at, record.data_len, "an index");
    for (std::uint32_t i = 0; i < count; ++i) {
        std::uint32_t offset;
        std::memcpy(&offset, entries.data() + 12 * i + 8, 4);
        if (offset >= chunk->size) bag.Fail(record.at, "an index entry points past its chunk");
        if (chunk->compressed) continue;
        // The message record at `offset` must fit in the chunk: header, data length, data.
        const std::uint64_t left = chunk->size - offset;
        const std::uint64_t at = chunk->data_at + offset;
        if (left < 8) bag.Fail(at, "a message record cut by its chunk's end");
        const std::uint32_t header_len = bag.U32(at, "a message header length");
        if (header_len > left - 8) bag.Fail(at, "a message header runs past its chunk");
        if (header_len > kMaxHeaderBytes)
            bag.Fail(at, "a message header of " + std::to_string(header_len) + " bytes");
        HeaderFields(bag, at, bag.Read(at + 4, header_len, "a message header"));
        const std::uint32_t data_len = bag.U32(at + 4 + header_len, "a message length");
        if (data_len > left - 8 - header_len) bag.Fail(at, "a message runs past its chunk");
    }
}

}  // namespace

void CheckBagStructure(const std::filesystem::path& file) {
    BagFile bag(file);
    const std::string version =
        bag.Read(0, std::min<std::uint64_t>(kVersionBytes, bag.size()), "the version line");
    if (version != kVersionLine) {
        throw ReadError(file,
                        "not a ROS 1 bag of format 2.0 (it does not start with "
                        "'#ROSBAG V2.0'): " +
                            core::Quoted(version));
    }
    std::set<std::uint64_t> records;
    std::set<std::uint64_t> chunks;
    std::vector<std::uint64_t> pointers;  // index_pos and chunk_pos values, checked at the end
    Chunk last_chunk;
    bool have_chunk = false;
    for (std::uint64_t at = kVersionBytes; at < bag.size();) {
        const Record record = ReadRecord(bag, at);
        records.insert(at);
        if (record.op == kOpBagHeader) {
            const std::uint64_t index_pos = Field64(bag, record, "index_pos");
            if (index_pos != 0) pointers.push_back(index_pos);  // 0: not yet indexed
        } else if (record.op == kOpChunk) {
            last_chunk = CheckChunk(bag, record);
            have_chunk = true;
            chunks.insert(at);
        } else if (record.op == kOpIndex) {
            CheckIndex(bag, record, have_chunk ? &last_chunk : nullptr);
        } else if (record.op == kOpChunkInfo) {
            const std::uint64_t chunk_pos = Field64(bag, record, "chunk_pos");
            if (chunks.count(chunk_pos) == 0)
                bag.Fail(record.at, "a chunk info that points at no chunk");
        } else if (record.op == kOpConnection) {
            // Its data is the connection header (topic, type, md5sum, message definition).
            if (record.data_len > kMaxHeaderBytes)
                bag.Fail(record.at,
                         "a connection header of " + std::to_string(record.data_len) + " bytes");
            HeaderFields(bag, record.at,
                         bag.Read(record.data_at, record.data_len, "a connection header"));
        } else if (record.op == kOpMessage) {
            bag.Fail(record.at, "a message record outside any chunk");
        }
        at = record.end;
    }
    for (const std::uint64_t pointer : pointers) {
        if (pointer != bag.size() && records.count(pointer) == 0)
            bag.Fail(pointer, "the bag header's index_pos points at no record");
    }
}

}  // namespace lidarloop::io::detail
