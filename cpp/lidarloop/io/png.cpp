#include "lidarloop/io/png.hpp"

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include <png.h>

#include "lidarloop/core/error.hpp"
#include "lidarloop/io/read_error.hpp"

namespace lidarloop::io {
namespace {

// libpng reports errors by longjmp. The error callback copies the message into this buffer and
// jumps back into WriteRows, whose locals are all trivially destructible so that nothing is
// skipped.
struct PngError {
    char message[256] = "";
};

void StoreErrorAndJump(png_structp png, png_const_charp message) {
    auto* error = static_cast<PngError*>(png_get_error_ptr(png));
    std::snprintf(error->message, sizeof(error->message), "%s", message);
    png_longjmp(png, 1);
}

void IgnoreWarning(png_structp, png_const_charp) {}

// Returns false (with the message in `error`) when libpng failed.
bool WriteRows(png_structp png, png_infop info, FILE* out, const Image& image) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, out);
    png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
                 static_cast<png_uint_32>(image.height), 8,
                 image.channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    const std::size_t row_bytes =
        static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.channels);
    for (int y = 0; y < image.height; ++y) {
        png_write_row(png, image.pixels.data() + static_cast<std::size_t>(y) * row_bytes);
    }
    png_write_end(png, nullptr);
    return true;
}

}  // namespace

void WritePng(const std::filesystem::path& file, const Image& image) {
    if (image.width <= 0 || image.height <= 0 || (image.channels != 1 && image.channels != 3) ||
        image.pixels.size() != static_cast<std::size_t>(image.width) *
                                   static_cast<std::size_t>(image.height) *
                                   static_cast<std::size_t>(image.channels)) {
        throw core::ConfigError("PNG image " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + "x" +
                                std::to_string(image.channels) + " does not match its " +
                                std::to_string(image.pixels.size()) + " bytes");
    }
    std::unique_ptr<FILE, int (*)(FILE*)> out(std::fopen(file.c_str(), "wb"), &std::fclose);
    if (!out) throw WriteError(file, std::string("cannot open (") + std::strerror(errno) + ")");
    PngError error;
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, StoreErrorAndJump, IgnoreWarning);
    png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
    const bool written = info != nullptr && WriteRows(png, info, out.get(), image);
    png_destroy_write_struct(&png, &info);
    if (!written) throw WriteError(file, std::string("PNG: ") + error.message);
    // fclose writes what fflush left and reports a full disk or a lost network file system.
    if (std::fclose(out.release()) != 0) throw WriteError(file, "writing the PNG failed");
}

}  // namespace lidarloop::io
