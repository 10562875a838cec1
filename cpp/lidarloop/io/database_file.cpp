#include "lidarloop/io/database_file.hpp"

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/detail/byte_stream.hpp"

namespace lidarloop::io {
namespace {
constexpr char kDatabaseMagic[] = "LLDB0001";
}  // namespace

void SaveDatabase(const std::filesystem::path& file, const pipeline::DescriptorDatabase& database,
                  const pipeline::DetectorConfig& detection) {
    core::ByteWriter out;
    out.PutMagic(kDatabaseMagic);
    RunConfig config;
    config.descriptor = database.config();
    config.detection = detection;
    out.PutString(DumpConfigYaml(config));
    out.Put<std::uint64_t>(database.size());
    for (std::size_t i = 0; i < database.size(); ++i) database.Encode(i, out);
    detail::WriteWholeFile(file, out.data());
}

StoredDatabase LoadStoredDatabase(const std::filesystem::path& file) {
    core::ByteReader in = detail::FileReader(file, detail::ReadWholeFile(file));
    in.ExpectMagic(kDatabaseMagic, "lidarloop database");
    RunConfig config;
    // Read before the try: its own error names the file already.
    const std::string yaml = in.GetString("configuration");
    try {
        ApplyConfigYaml(yaml, "embedded config", config, LegacyKeys::kMigrate);
    } catch (const ReadError& e) {
        in.Fail(e.what());
    }
    pipeline::DescriptorDatabase database(config.descriptor);
    const auto count = in.Get<std::uint64_t>("scan count");
    in.RequireItems(count, 9, "scans");
    for (std::uint64_t i = 0; i < count; ++i) database.Decode(in);
    if (!in.AtEnd()) in.Fail("trailing bytes after " + std::to_string(count) + " scans");
    return {std::move(database), config.detection};
}

pipeline::DescriptorDatabase LoadDatabase(const std::filesystem::path& file) {
    return LoadStoredDatabase(file).database;
}

}  // namespace lidarloop::io
