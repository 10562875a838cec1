#include "lidarloop/io/prepared_scans_file.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <string_view>

#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/detail/byte_stream.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

// 0002: structure_roughness_m is the scan's self-residual (issue 24); 0001 stored a median
// plane residual that the acceptance rule no longer understands.
constexpr char kPreparedScansMagic[] = "LLPS0002";
constexpr char kOldMagic[] = "LLPS0001";
constexpr std::size_t kPointBytes = 6 * sizeof(float);  // x y z and the normal

void PutSurface(core::ByteWriter& out, const registration::SurfacePoints& surface) {
    out.Put<std::uint64_t>(surface.size());
    for (std::size_t i = 0; i < surface.size(); ++i) {
        out.PutArray(surface.points()[i].data(), 3);
        out.PutArray(surface.normals()[i].data(), 3);
    }
}

std::shared_ptr<const registration::SurfacePoints> GetSurface(core::ByteReader& in,
                                                              const char* what) {
    const auto count = in.Get<std::uint64_t>(what);
    in.RequireItems(count, kPointBytes, what);
    std::vector<Eigen::Vector3f> points(count);
    std::vector<Eigen::Vector3f> normals(count);
    for (std::uint64_t i = 0; i < count; ++i) {
        in.GetArray(points[i].data(), 3, what);
        in.GetArray(normals[i].data(), 3, what);
        if (!points[i].allFinite() || !normals[i].allFinite()) {
            in.Fail(std::string("non-finite value in ") + what);
        }
    }
    return std::make_shared<const registration::SurfacePoints>(std::move(points),
                                                               std::move(normals));
}

void PutScan(core::ByteWriter& out, const registration::PreparedScan& scan) {
    const bool present = scan.structure && scan.ground;
    out.Put<std::uint8_t>(present ? 1 : 0);
    if (!present) return;
    out.Put<std::uint64_t>(scan.input_points);
    out.Put<std::uint64_t>(scan.usable_points);
    out.Put<double>(scan.structure_roughness_m);
    PutSurface(out, *scan.structure);
    out.Put<std::uint64_t>(scan.structure_distinctive.size());
    out.PutArray(scan.structure_distinctive.data(), scan.structure_distinctive.size());
    PutSurface(out, *scan.ground);
}

registration::PreparedScan GetScan(core::ByteReader& in) {
    registration::PreparedScan scan;
    if (in.Get<std::uint8_t>("scan flag") == 0) return scan;
    scan.input_points = in.Get<std::uint64_t>("input point count");
    scan.usable_points = in.Get<std::uint64_t>("usable point count");
    scan.structure_roughness_m = in.Get<double>("roughness");
    if (!std::isfinite(scan.structure_roughness_m) || scan.structure_roughness_m < 0.0) {
        in.Fail("roughness is not a finite number >= 0");
    }
    scan.structure = GetSurface(in, "structure points");
    const auto flags = in.Get<std::uint64_t>("distinctive flag count");
    if (flags != scan.structure->size()) {
        in.Fail("distinctive flags do not match the structure points");
    }
    scan.structure_distinctive.resize(flags);
    in.GetArray(scan.structure_distinctive.data(), flags, "distinctive flags");
    scan.ground = GetSurface(in, "ground points");
    return scan;
}

void Append(std::ofstream& out, const core::ByteWriter& bytes) {
    out.write(bytes.data().data(), static_cast<std::streamsize>(bytes.data().size()));
}

// Writes `count` scans, scan i written by `put_scan(i, bytes)`, one in memory at a time:
// encoding the whole file first held a second copy of every prepared scan at the end of a long
// run, the peak of its memory.
void SaveScans(const std::filesystem::path& file, std::size_t count,
               const std::function<void(std::size_t, core::ByteWriter&)>& put_scan,
               const registration::ScanReductionConfig& reduction) {
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/true);
    core::ByteWriter header;
    header.PutMagic(kPreparedScansMagic);
    RunConfig config;
    config.detection.verification.reduction = reduction;
    header.PutString(DumpConfigYaml(config));
    header.Put<std::uint64_t>(count);
    Append(out, header);
    core::ByteWriter bytes;  // one buffer for all scans
    for (std::size_t i = 0; i < count; ++i) {
        bytes.Clear();
        put_scan(i, bytes);
        Append(out, bytes);
    }
    out.close();
    if (!out) throw WriteError(file, "writing the prepared scans failed (disk full?)");
}

}  // namespace

void SavePreparedScans(const std::filesystem::path& file,
                       const std::vector<registration::PreparedScan>& scans,
                       const registration::ScanReductionConfig& reduction) {
    SaveScans(
        file, scans.size(),
        [&](std::size_t i, core::ByteWriter& bytes) { PutScan(bytes, scans[i]); }, reduction);
}

void SavePreparedScans(const std::filesystem::path& file,
                       const std::vector<registration::CompactPreparedScan>& scans,
                       const registration::ScanReductionConfig& reduction) {
    SaveScans(
        file, scans.size(),
        [&](std::size_t i, core::ByteWriter& bytes) { PutScan(bytes, scans[i].Expand()); },
        reduction);
}

StoredPreparedScans LoadPreparedScans(const std::filesystem::path& file) {
    core::ByteReader in = detail::FileReader(file, detail::ReadWholeFile(file));
    if (in.StartsWith(kOldMagic)) {
        in.Fail(
            "written by an earlier lidarloop (another roughness measure); run detect again "
            "to rebuild it");
    }
    in.ExpectMagic(kPreparedScansMagic, "lidarloop prepared scans");
    RunConfig config;
    // Read before the try: its own error names the file already.
    const std::string yaml = in.GetString("configuration");
    try {
        ApplyConfigYaml(yaml, "embedded config", config);
    } catch (const ReadError& e) {
        in.Fail(e.what());
    }
    StoredPreparedScans stored;
    stored.reduction = config.detection.verification.reduction;
    const auto count = in.Get<std::uint64_t>("scan count");
    in.RequireItems(count, 1, "scans");
    stored.scans.reserve(count);
    for (std::uint64_t i = 0; i < count; ++i) stored.scans.push_back(GetScan(in));
    if (!in.AtEnd()) in.Fail("trailing bytes after " + std::to_string(count) + " scans");
    return stored;
}

std::filesystem::path PreparedScansPathOf(const std::filesystem::path& database_file) {
    std::filesystem::path path = database_file;
    return path.replace_extension(".scans");
}

bool IsPreparedScansFile(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    char start[sizeof(kPreparedScansMagic) - 1] = {};
    if (!in.read(start, sizeof(start))) return false;
    const std::string_view magic(start, sizeof(start));
    return magic == kPreparedScansMagic || magic == kOldMagic;
}

}  // namespace lidarloop::io
