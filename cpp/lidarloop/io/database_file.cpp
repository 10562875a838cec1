#include "lidarloop/io/database_file.hpp"

#include <cmath>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/detail/byte_stream.hpp"

namespace lidarloop::io {
namespace {

constexpr char kMagic[] = "LLDB0001";
constexpr std::uint32_t kMaxMatrixEntries = 1u << 24;

void PutNdtSet(detail::ByteWriter& out, const core::NdtDescriptorSet& set) {
    out.Put<std::uint32_t>(static_cast<std::uint32_t>(set.descriptors.size()));
    for (const core::NdtDescriptor& f : set.descriptors) {
        out.Put<std::uint32_t>(static_cast<std::uint32_t>(f.rows));
        out.Put<std::uint32_t>(static_cast<std::uint32_t>(f.cols));
        out.Put<double>(f.total);
        out.PutArray(f.counts.data(), f.counts.size());
        out.PutArray(f.R_aligned_sensor.data(), 9);
    }
}

core::NdtDescriptorSet GetNdtSet(detail::ByteReader& in) {
    core::NdtDescriptorSet set;
    const auto count = in.Get<std::uint32_t>("NDT descriptor count");
    in.RequireItems(count, 16, "NDT descriptors");
    for (std::uint32_t d = 0; d < count; ++d) {
        const auto rows = in.Get<std::uint32_t>("NDT rows");
        const auto cols = in.Get<std::uint32_t>("NDT columns");
        const std::uint64_t entries = std::uint64_t{rows} * cols;
        if (entries > kMaxMatrixEntries) in.Fail("absurd NDT descriptor size");
        const auto stored_total = in.Get<double>("NDT cell total");
        std::vector<float> counts(entries);
        in.GetArray(counts.data(), counts.size(), "NDT counts");
        core::NdtDescriptor f;
        in.GetArray(f.R_aligned_sensor.data(), 9, "NDT rotation");
        try {
            core::SetNdtCounts(f, static_cast<int>(rows), static_cast<int>(cols),
                               std::move(counts));
        } catch (const core::ConfigError& error) {
            in.Fail(error.what());
        }
        // Counts are whole numbers, so their sum is exact: any difference is a damaged file.
        if (!(std::abs(f.total - stored_total) < 0.5))
            in.Fail("NDT cell total differs from its counts");
        set.descriptors.push_back(std::move(f));
    }
    return set;
}

}  // namespace

void SaveDatabase(const std::filesystem::path& file, const pipeline::DescriptorDatabase& database) {
    detail::ByteWriter out;
    out.PutMagic(kMagic);
    RunConfig config;
    config.descriptor = database.config();
    out.PutString(DumpConfigYaml(config));
    out.Put<std::uint64_t>(database.size());
    const pipeline::CumulativeHistograms* rows = database.histograms();
    for (std::size_t i = 0; i < database.size(); ++i) {
        out.Put<double>(database.TimeS(i));
        out.Put<std::uint8_t>(database.IsValid(i) ? 1 : 0);
        if (rows != nullptr) {
            out.PutArray(rows->Row(i), static_cast<std::size_t>(rows->stride()));
        } else {
            PutNdtSet(out, database.ndt_sets()[i]);
        }
    }
    detail::WriteWholeFile(file, out.data());
}

pipeline::DescriptorDatabase LoadDatabase(const std::filesystem::path& file) {
    detail::ByteReader in(file, detail::ReadWholeFile(file));
    in.ExpectMagic(kMagic, "lidarloop database");
    RunConfig config;
    try {
        ApplyConfigYaml(in.GetString("configuration"), "embedded config", config,
                        LegacyKeys::kIgnore);
    } catch (const ReadError& e) {
        in.Fail(e.what());
    }
    pipeline::DescriptorDatabase database(config.descriptor);
    const auto count = in.Get<std::uint64_t>("scan count");
    in.RequireItems(count, 9, "scans");
    const pipeline::CumulativeHistograms* rows = database.histograms();
    std::vector<float> row(rows != nullptr ? static_cast<std::size_t>(rows->stride()) : 0);
    for (std::uint64_t i = 0; i < count; ++i) {
        const auto time_s = in.Get<double>("scan time");
        const bool valid = in.Get<std::uint8_t>("valid flag") != 0;
        if (rows != nullptr) {
            in.GetArray(row.data(), row.size(), "cumulative histogram");
            database.AddCumulativeRow(row, time_s, valid);
        } else {
            database.AddNdtSet(GetNdtSet(in), time_s, valid);
        }
    }
    if (!in.AtEnd()) in.Fail("trailing bytes after " + std::to_string(count) + " scans");
    return database;
}

}  // namespace lidarloop::io
