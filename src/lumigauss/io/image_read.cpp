// Reading images: OpenEXR through tinyexr, everything else (PNG, JPEG, Radiance HDR, ...) through stb_image.
#include <stb/stb_image.h>
#include <tinyexr.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "lumigauss/io/image.h"
#include "lumigauss/io/radiance_scanlines.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

void require_regular_file(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) fail_in_file(path, "image file not found");
}

// Sniffed from the content, not the extension: OpenEXR files start with the magic number 76 2f 31 01.
bool is_exr(const std::string& path) {
    unsigned char magic[4] = {};
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) fail_in_file(path, "cannot open the image file");
    const std::size_t n = std::fread(magic, 1, 4, f);
    std::fclose(f);
    return n == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
}

std::string stb_reason() {
    const char* r = stbi_failure_reason();
    return r ? r : "unknown reason";
}

// Takes ownership of a tinyexr error string and turns it into an Error naming the file.
[[noreturn]] void fail_exr(const std::string& path, const std::string& what, const char* err) {
    const std::string detail = err ? err : "unknown reason";
    if (err) FreeEXRErrorMessage(err);
    fail_in_file(path, what + " (" + detail + ")");
}

ImageInfo exr_info(const std::string& path) {
    EXRVersion version;
    if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS)
        fail_in_file(path, "corrupt OpenEXR header");
    if (version.multipart || version.non_image)
        fail_in_file(path, "multi-part and deep OpenEXR are not supported");
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    if (ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS) {
        FreeEXRHeader(&header);  // what it parsed before failing (found leaking by fuzz_image)
        fail_exr(path, "corrupt OpenEXR header", err);
    }
    ImageInfo info;
    info.width = header.data_window.max_x - header.data_window.min_x + 1;
    info.height = header.data_window.max_y - header.data_window.min_y + 1;
    bool has_alpha = false;
    for (int i = 0; i < header.num_channels; ++i) has_alpha |= std::strcmp(header.channels[i].name, "A") == 0;
    info.channels = header.num_channels == 1 ? 1 : (has_alpha ? 4 : 3);
    FreeEXRHeader(&header);
    return info;
}

Image read_exr(const std::string& path) {
    const ImageInfo info = exr_info(path);
    float* rgba = nullptr;
    int w = 0, h = 0;
    const char* err = nullptr;
    if (LoadEXR(&rgba, &w, &h, path.c_str(), &err) != TINYEXR_SUCCESS)
        fail_exr(path, "cannot decode OpenEXR", err);
    const std::unique_ptr<float, decltype(&std::free)> owner(rgba, &std::free);
    Image image(w, h, 4);
    std::memcpy(image.pixels.data(), rgba, image.pixels.size() * sizeof(float));
    return info.channels == 4 ? image : to_channels(image, info.channels);
}

// stb_image decodes to 8-bit, 16-bit or float samples; dividing by `max_code` maps codes to [0, 1] exactly as
// value/255 or value/65535 (1 for float data).
template <typename Sample, typename Load>
Image decode_with_stb(const std::string& path, Load load, float max_code) {
    int w = 0, h = 0, c = 0;
    Sample* data = load(path.c_str(), &w, &h, &c, 0);
    if (!data) fail_in_file(path, "unsupported or corrupt image (" + stb_reason() + ")");
    const std::unique_ptr<Sample, decltype(&stbi_image_free)> owner(data, &stbi_image_free);
    Image image(w, h, c);
    for (std::size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = float(data[i]) / max_code;
    return image;
}

// PNG's numbers: big-endian 32-bit.
std::uint32_t png_uint32(const unsigned char* bytes) {
    return (std::uint32_t(bytes[0]) << 24) | (std::uint32_t(bytes[1]) << 16) |
           (std::uint32_t(bytes[2]) << 8) | std::uint32_t(bytes[3]);
}

// Width and height from a PNG's IHDR chunk (signature, length, "IHDR", two big-endian 32-bit numbers).
std::optional<ImageInfo> png_header_size(const std::string& path) {
    unsigned char head[24] = {};
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return std::nullopt;
    const std::size_t n = std::fread(head, 1, sizeof head, f);
    std::fclose(f);
    if (n != sizeof head || std::memcmp(head, "\x89PNG\r\n\x1a\n", 8) != 0 ||
        std::memcmp(head + 12, "IHDR", 4) != 0)
        return std::nullopt;
    const std::uint32_t width = png_uint32(head + 16), height = png_uint32(head + 20);
    if (width > 0x7fffffffu || height > 0x7fffffffu) return std::nullopt;
    return ImageInfo{int(width), int(height), 0};
}

void require_pixel_limit(const std::string& path, const ImageInfo& info) {
    if (info.width <= 0 || info.height <= 0)
        fail_in_file(path, "the image declares " + std::to_string(info.width) + " x " +
                               std::to_string(info.height) + " pixels");
    if (static_cast<long long>(info.width) * info.height > kMaxImagePixels)
        fail_in_file(path, "the image declares " + std::to_string(info.width) + " x " +
                               std::to_string(info.height) + " pixels, more than the limit of " +
                               std::to_string(kMaxImagePixels) + " (16384 x 8192)");
}

// The file's size in bytes; an Error naming it if it cannot be read.
std::uint64_t file_bytes(const std::string& path) {
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) fail_in_file(path, "cannot read the file size (" + ec.message() + ")");
    return size;
}

// No image format decodes to more samples than this per byte of file: deflate (PNG, EXR ZIP) expands at most
// 1032:1, a 1-bit palette PNG packs 8 pixels per byte and expands to 4 channels, and run-length and JPEG
// entropy codes stay below that. A file declaring more is lying about its size, and is refused before stb or
// tinyexr allocate for it: memory stays proportional to the file (a 100-byte file: at most 13 MB of floats).
constexpr double kMaxSamplesPerFileByte = 32768;

void require_plausible_size(const std::string& path, const ImageInfo& info) {
    const std::uint64_t bytes = file_bytes(path);
    const double samples = double(info.width) * double(info.height) * double(std::max(info.channels, 1));
    if (samples > kMaxSamplesPerFileByte * double(bytes))
        fail_in_file(path, "the image declares " + std::to_string(info.width) + " x " +
                               std::to_string(info.height) + " pixels, more than a file of " +
                               std::to_string(bytes) + " bytes can hold (truncated or corrupt)");
}

// stb_image decodes a cut .hdr as if the missing scanlines were black; refuse it instead.
void require_complete_radiance(const std::string& path) {
    const std::string bytes = read_text_file(path);  // binary mode, whole file
    const std::span<const std::uint8_t> file(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                             bytes.size());
    RadianceLayout layout;
    if (!parse_radiance_layout(file, layout))
        fail_in_file(path,
                     "corrupt Radiance HDR header (no '#?' signature, no blank line, or no resolution line)");
    const int complete = complete_radiance_scanlines(file, layout);
    if (complete < layout.height)
        fail_in_file(path, "truncated or corrupt Radiance HDR: " + std::to_string(complete) + " of " +
                               std::to_string(layout.height) + " scanlines are complete");
}

// A chunk type for a message: bytes outside printable ASCII as '?'.
std::string printable(std::string text) {
    for (char& c : text)
        if (c < 0x20 || c > 0x7e) c = '?';
    return text;
}

// stb_image grows its buffer to the length a PNG chunk declares before reading it (a 210-byte file whose
// chunk declared 1 GB asked for 2 GB; found by fuzz_image): every chunk must fit in the file.
void require_png_chunks_in_file(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) fail_in_file(path, "cannot open the image");
    const std::unique_ptr<std::FILE, decltype(&std::fclose)> owner(f, &std::fclose);
    unsigned char head[8];
    if (std::fread(head, 1, 8, f) != 8 || std::memcmp(head, "\x89PNG\r\n\x1a\n", 8) != 0)
        return;  // not a PNG
    const std::uint64_t size = file_bytes(path);
    std::uint64_t at = 8;
    while (at + 8 <= size) {
        if (std::fseek(f, long(at), SEEK_SET) != 0 || std::fread(head, 1, 8, f) != 8) break;
        const std::uint64_t length = png_uint32(head);
        const std::string type(reinterpret_cast<const char*>(head + 4), 4);
        if (at + 12 + length > size)
            fail_in_file(path, "truncated or corrupt PNG: chunk '" + printable(type) + "' at byte " +
                                   std::to_string(at) + " declares " + std::to_string(length) +
                                   " bytes, the file has " + std::to_string(size - at) + " left");
        if (type == "IEND") break;
        at += 12 + length;
    }
}

// stb_image reads the pixels a TGA lacks as zeros (found by fuzz_image: a 4 KB file declaring 12336 x 2608
// decoded to 515 MB). stb tries TGA after every format with a signature, so a file whose 18-byte header reads
// as a TGA of the size stb reported is checked: uncompressed, the file must hold every pixel; run-length
// encoded, a packet of 1 + pixel bytes holds at most 128 pixels.
void require_complete_tga(const std::string& path, const ImageInfo& info) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) fail_in_file(path, "cannot open the image");
    const std::unique_ptr<std::FILE, decltype(&std::fclose)> owner(f, &std::fclose);
    unsigned char h[18];
    if (std::fread(h, 1, 18, f) != 18) return;
    const int type = h[2], width = h[12] | (h[13] << 8), height = h[14] | (h[15] << 8);
    const bool uncompressed = type >= 1 && type <= 3, run_length = type >= 9 && type <= 11;
    if (!(uncompressed || run_length) || width != info.width || height != info.height) return;  // not a TGA
    const std::uint64_t size = file_bytes(path);
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
    const std::uint64_t pixel_bytes = std::max(1, (h[16] + 7) / 8);
    const std::uint64_t palette = h[1] == 1 ? std::uint64_t(h[5] | (h[6] << 8)) * ((h[7] + 7) / 8) : 0;
    const std::uint64_t header = 18 + std::uint64_t(h[0]) + palette;
    const std::uint64_t data = size > header ? size - header : 0;
    const bool complete =
        uncompressed ? data >= pixels * pixel_bytes : pixels <= 128 * (data / (1 + pixel_bytes));
    if (!complete)
        fail_in_file(path, "truncated or corrupt TGA: it declares " + std::to_string(width) + " x " +
                               std::to_string(height) + " pixels, the file holds " + std::to_string(data) +
                               " bytes of pixel data");
}

}  // namespace

ImageInfo read_image_info(const std::string& path) {
    require_regular_file(path);
    if (is_exr(path)) return exr_info(path);
    ImageInfo info;
    if (!stbi_info(path.c_str(), &info.width, &info.height, &info.channels)) {
        // stb refuses a PNG over 1 GiB of samples as "unknown image type": say what the header declares.
        if (const std::optional<ImageInfo> declared = png_header_size(path))
            require_pixel_limit(path, *declared);
        fail_in_file(path, "unsupported or corrupt image (" + stb_reason() + ")");
    }
    return info;
}

Image read_image(const std::string& path) {
    const ImageInfo info = read_image_info(path);
    require_pixel_limit(path, info);
    require_plausible_size(path, info);
    if (is_exr(path)) return read_exr(path);
    // Radiance HDR is float radiance. stbi_loadf is used for it only: on 8-bit files it would apply a gamma.
    if (stbi_is_hdr(path.c_str())) {
        require_complete_radiance(path);
        return decode_with_stb<float>(path, stbi_loadf, 1.0f);
    }
    require_png_chunks_in_file(path);
    require_complete_tga(path, info);
    if (stbi_is_16_bit(path.c_str())) return decode_with_stb<stbi_us>(path, stbi_load_16, 65535.0f);
    return decode_with_stb<stbi_uc>(path, stbi_load, 255.0f);
}

}  // namespace lumigauss
