// Writing images: PNG through libpng (8 and 16 bit), OpenEXR float32 through tinyexr. Both atomic.
#include <png.h>
#include <tinyexr.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <string>
#include <vector>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/image.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

struct PngErrorState {
    char message[256] = "unknown libpng error";
};

void on_png_error(png_structp png, png_const_charp msg) {
    auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
    std::snprintf(state->message, sizeof state->message, "%s", msg);
    png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

// libpng reports errors by longjmp. Only C objects live between the setjmp and the returns below, so the jump
// skips no destructor; the caller owns every C++ object (rows, file).
bool encode_png(std::FILE* f, const Image& image, int bits, png_bytep* rows, PngErrorState* state) {
    static constexpr int kColorTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                          PNG_COLOR_TYPE_RGB_ALPHA};
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, state, on_png_error, on_png_warning);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), bits,
                 kColorTypes[image.channels - 1], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    // Fast deflate and one filter: renders, orbits, eval sheets and training previews write many images, and
    // libpng's defaults (level 6, every filter tried per row) took longer than rendering them. Measured on a
    // render's ten 320 x 240 maps and on twelve eval sheets: 4.3x and 3.7x faster, 19 % and 14 % more bytes
    // (OpenCV's imwrite also defaults to level 1).
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_PAETH);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

// Samples as PNG stores them: clamped, rounded, big-endian for 16 bit.
std::vector<unsigned char> png_samples(const Image& image, int bits) {
    const int bytes = bits / 8;
    const float max_code = bits == 16 ? 65535.0f : 255.0f;
    std::vector<unsigned char> out(image.pixels.size() * bytes);
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        const float v = std::isnan(image.pixels[i]) ? 0.0f : std::clamp(image.pixels[i], 0.0f, 1.0f);
        const auto code = static_cast<unsigned>(std::lround(v * max_code));
        if (bytes == 2) out[2 * i] = static_cast<unsigned char>(code >> 8);
        out[bytes * i + bytes - 1] = static_cast<unsigned char>(code & 0xffu);
    }
    return out;
}

void check_writable(const std::string& path, const Image& image, int max_channels) {
    if (image.empty() || image.channels < 1 || image.channels > max_channels ||
        image.pixels.size() != std::size_t(image.width) * image.height * image.channels)
        fail_in_file(path, "cannot write an image of " + std::to_string(image.width) + "x" +
                               std::to_string(image.height) + "x" + std::to_string(image.channels));
}

}  // namespace

void write_png(const std::string& path, const Image& image, int bits) {
    check_writable(path, image, 4);
    if (bits != 8 && bits != 16)
        fail_in_file(path, "PNG bit depth must be 8 or 16, not " + std::to_string(bits));
    std::vector<unsigned char> samples = png_samples(image, bits);
    const std::size_t row_bytes = std::size_t(image.width) * image.channels * (bits / 8);
    std::vector<png_bytep> rows(image.height);
    for (int y = 0; y < image.height; ++y) rows[y] = samples.data() + y * row_bytes;
    write_atomically(path, [&](const std::string& tmp) {
        std::FILE* f = std::fopen(tmp.c_str(), "wb");
        if (!f) fail_in_file(path, "cannot open " + tmp + " for writing (does the folder exist?)");
        PngErrorState state;
        const bool encoded = encode_png(f, image, bits, rows.data(), &state);
        const bool closed = std::fclose(f) == 0;
        if (!encoded) fail_in_file(path, std::string("PNG encoding failed: ") + state.message);
        if (!closed) fail_in_file(path, "write failed (disk full?)");
    });
}

void write_exr(const std::string& path, const Image& image) {
    check_writable(path, image, 4);
    if (image.channels == 2) fail_in_file(path, "OpenEXR output needs 1, 3 or 4 channels, not 2");
    write_atomically(path, [&](const std::string& tmp) {
        const char* err = nullptr;
        if (SaveEXR(image.pixels.data(), image.width, image.height, image.channels, 0, tmp.c_str(), &err) !=
            TINYEXR_SUCCESS) {
            const std::string detail = err ? err : "unknown reason";
            if (err) FreeEXRErrorMessage(err);
            fail_in_file(path, "OpenEXR write failed (" + detail + ")");
        }
    });
}

}  // namespace lumigauss
