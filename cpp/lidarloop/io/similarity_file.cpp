#include "lidarloop/io/similarity_file.hpp"

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/detail/byte_stream.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"

namespace lidarloop::io {
namespace {
constexpr char kMagic[] = "LLSIM001";
}  // namespace

void WriteSimilarityMatrix(const std::filesystem::path& file,
                           const pipeline::SimilarityMatrix& matrix, core::Method method) {
    detail::ByteWriter out;
    out.PutMagic(kMagic);
    out.PutString(core::ToString(method));
    out.Put<std::uint64_t>(matrix.size());
    out.PutArray(matrix.condensed().data(), matrix.condensed().size());
    detail::WriteWholeFile(file, out.data());
}

StoredSimilarity ReadSimilarityMatrix(const std::filesystem::path& file) {
    core::ByteReader in = detail::FileReader(file, detail::ReadWholeFile(file));
    in.ExpectMagic(kMagic, "lidarloop similarity matrix");
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
