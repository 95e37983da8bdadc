// Reading images: OpenEXR through tinyexr, everything else (PNG, JPEG, Radiance HDR, ...) through stb_image.
#include <stb/stb_image.h>
#include <tinyexr.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include "lumigauss/io/image.h"
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
    if (ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS)
        fail_exr(path, "corrupt OpenEXR header", err);
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

}  // namespace

ImageInfo read_image_info(const std::string& path) {
    require_regular_file(path);
    if (is_exr(path)) return exr_info(path);
    ImageInfo info;
    if (!stbi_info(path.c_str(), &info.width, &info.height, &info.channels))
        fail_in_file(path, "unsupported or corrupt image (" + stb_reason() + ")");
    return info;
}

Image read_image(const std::string& path) {
    require_regular_file(path);
    if (is_exr(path)) return read_exr(path);
    // Radiance HDR is float radiance. stbi_loadf is used for it only: on 8-bit files it would apply a gamma.
    if (stbi_is_hdr(path.c_str())) return decode_with_stb<float>(path, stbi_loadf, 1.0f);
    if (stbi_is_16_bit(path.c_str())) return decode_with_stb<stbi_us>(path, stbi_load_16, 65535.0f);
    return decode_with_stb<stbi_uc>(path, stbi_load, 255.0f);
}

}  // namespace lumigauss
