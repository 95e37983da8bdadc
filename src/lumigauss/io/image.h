#pragma once
// Float images and their files. Pixel values are kept as stored: 8-bit and 16-bit PNG/JPEG become value/255
// or value/65535 (no sRGB linearisation; use srgb_to_linear where a linear value is wanted), Radiance .hdr
// and OpenEXR stay float radiance. Channels are interleaved, rows top to bottom.
#include <cstddef>
#include <string>
#include <vector>

namespace lumigauss {

struct Image {
    int width = 0, height = 0, channels = 0;
    std::vector<float> pixels;  // row-major, interleaved: pixels[(y * width + x) * channels + c]

    Image() = default;
    Image(int w, int h, int c, float fill = 0.0f)
        : width(w), height(h), channels(c), pixels(std::size_t(w) * h * c, fill) {}

    std::size_t index(int x, int y, int c) const { return (std::size_t(y) * width + x) * channels + c; }
    float& at(int x, int y, int c) { return pixels[index(x, y, c)]; }
    float at(int x, int y, int c) const { return pixels[index(x, y, c)]; }
    bool empty() const { return pixels.empty(); }
};

// What a file's header says, read without decoding the pixels.
struct ImageInfo {
    int width = 0, height = 0, channels = 0;
};

// The largest image any reader accepts: 16384 x 8192 (a 16K panorama), 134 megapixels, 2 GiB as RGBA floats.
// A file that declares more is refused before its pixels are allocated.
inline constexpr long long kMaxImagePixels = 16384LL * 8192LL;

// Size and channel count from the header (PNG, JPEG, HDR, EXR, and what else stb_image reads).
// Throws Error naming the file if it is missing or not a readable image.
ImageInfo read_image_info(const std::string& path);

// PNG (8/16 bit), JPEG, Radiance .hdr, OpenEXR. Gray stays 1 channel, gray+alpha 2, RGB 3, RGBA 4; an EXR
// gives 1 channel if it has one, 4 if it has an alpha channel, else 3 (R, G, B).
// Throws Error naming the file if it is missing, corrupt, cut short (Radiance .hdr), larger than
// kMaxImagePixels, declaring more pixels than its bytes can encode, or of an unsupported format.
Image read_image(const std::string& path);

// 8 or 16 bit PNG with the image's channel count (1 to 4). Values are clamped to [0, 1] (NaN -> 0) and
// rounded to the nearest code. Atomic: written to path + ".tmp", then renamed.
void write_png(const std::string& path, const Image& image, int bits = 8);

// float32 OpenEXR with 1, 3 or 4 channels (Y, RGB, RGBA). Atomic like write_png.
void write_exr(const std::string& path, const Image& image);

// Area (box) resampling: each output pixel is the area-weighted mean of the source pixels its footprint
// covers, the whole source extent mapping onto the whole output extent (corner to corner, as Camera::resized
// assumes). Downscaling by an integer factor that divides the size averages factor x factor blocks exactly.
Image resize_area(const Image& image, int new_width, int new_height);

// Copies of `image` with `channels` channels: gray is replicated to RGB, extra channels (alpha) are dropped.
Image to_channels(const Image& image, int channels);

// The standard piecewise sRGB transfer functions (IEC 61966-2-1).
float srgb_to_linear(float encoded);
float linear_to_srgb(float linear);

}  // namespace lumigauss
