#include "lidarloop/io/similarity_file.hpp"

#include <algorithm>
#include <fstream>
#include <vector>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/detail/byte_stream.hpp"
#include "lidarloop/io/detail/text_parsing.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::io {
namespace {
constexpr char kSimilarityMagic[] = "LLSIM001";
}  // namespace

void WriteSimilarityMatrix(const std::filesystem::path& file,
                           const pipeline::SimilarityMatrix& matrix, core::Method method) {
    detail::ByteWriter header;
    header.PutMagic(kSimilarityMagic);
    header.PutString(core::ToString(method));
    header.Put<std::uint64_t>(matrix.size());
    // The distances in blocks, not assembled in memory: they can be gigabytes.
    std::ofstream out = detail::OpenForWriting(file, /*binary=*/true);
    out.write(header.data().data(), static_cast<std::streamsize>(header.data().size()));
    constexpr std::size_t kBlock = std::size_t{1} << 18;  // distances, 1 MiB
    std::vector<char> bytes(kBlock * sizeof(float));
    const std::vector<float>& values = matrix.condensed();
    for (std::size_t begin = 0; begin < values.size() && out; begin += kBlock) {
        const std::size_t count = std::min(kBlock, values.size() - begin);
        for (std::size_t k = 0; k < count; ++k)
            detail::StoreLittle(values[begin + k], bytes.data() + k * sizeof(float));
        out.write(bytes.data(), static_cast<std::streamsize>(count * sizeof(float)));
    }
    out.close();
    if (!out) {
        throw WriteError(file, "writing " + std::to_string(values.size()) + " distances failed");
    }
}

StoredSimilarity ReadSimilarityMatrix(const std::filesystem::path& file) {
    core::ByteReader in = detail::FileReader(file, detail::ReadWholeFile(file));
    in.ExpectMagic(kSimilarityMagic, "lidarloop similarity matrix");
    StoredSimilarity stored;
    try {
        stored.method = pipeline::ParseMethod(in.GetString("method name"));
    } catch (const core::ConfigError& e) {
        in.Fail(e.what());
    }
    const auto n = in.Get<std::uint64_t>("scan count");
    if (n > (std::uint64_t{1} << 32)) in.Fail("absurd scan count " + std::to_string(n));
    const std::uint64_t pairs = n > 1 ? n * (n - 1) / 2 : 0;
    in.RequireItems(pairs, sizeof(float), "distances");
    stored.matrix = pipeline::SimilarityMatrix(static_cast<std::size_t>(n));
    in.GetArray(stored.matrix.condensed().data(), stored.matrix.condensed().size(), "distances");
    if (!in.AtEnd()) in.Fail("trailing bytes after " + std::to_string(pairs) + " distances");
    return stored;
}

}  // namespace lidarloop::io
