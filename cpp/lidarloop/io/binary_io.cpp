#include "lidarloop/io/detail/binary_io.hpp"

#include <system_error>

#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io::detail {

std::string BytesText(std::optional<std::size_t> bytes) {
    if (!bytes) return "more than " + std::to_string(std::numeric_limits<std::size_t>::max());
    return std::to_string(*bytes);
}

std::size_t FileSize(const std::filesystem::path& file) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    if (ec) throw ReadError(file, "cannot get the file size (" + ec.message() + ")");
    return static_cast<std::size_t>(size);
}

std::string ReadWholeFile(const std::filesystem::path& file) {
    std::ifstream in = OpenForReading(file, /*binary=*/true);
    std::string bytes(FileSize(file), '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (in.gcount() != static_cast<std::streamsize>(bytes.size())) {
        throw ReadError(file, "read " + std::to_string(in.gcount()) + " of " +
                                  std::to_string(bytes.size()) + " bytes");
    }
    return bytes;
}

void WriteWholeFile(const std::filesystem::path& file, const std::string& bytes) {
    std::ofstream out = OpenForWriting(file, /*binary=*/true);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw WriteError(file, "writing " + std::to_string(bytes.size()) + " bytes failed");
}

DataStream OpenDataAfterHeader(const std::filesystem::path& file, std::size_t header_lines) {
    DataStream data{OpenForReading(file, /*binary=*/true)};
    for (std::size_t i = 0; i < header_lines; ++i) {
        data.in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    }
    const std::size_t size = FileSize(file);
    const auto offset = data.in.eof() ? size : static_cast<std::size_t>(data.in.tellg());
    data.remaining = size - std::min(size, offset);
    return data;
}

std::vector<char> ReadDataBytes(const std::filesystem::path& file, DataStream& data,
                                std::size_t count) {
    std::vector<char> bytes(count);
    data.in.read(bytes.data(), static_cast<std::streamsize>(count));
    if (static_cast<std::size_t>(data.in.gcount()) != count) {
        throw ReadError(file, "read failed after " + std::to_string(data.in.gcount()) + " of " +
                                  std::to_string(count) + " data bytes");
    }
    data.remaining -= count;
    return bytes;
}

}  // namespace lidarloop::io::detail
