#include "lumigauss/io/image.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

// Which source channel feeds output channel k (-1: an opaque alpha of 1). Colour comes from the gray channel
// when the source has no colour; alpha is the source's last channel when it has one (2 or 4 channels).
int source_channel(int src_channels, int dst_channels, int k) {
    const bool src_alpha = src_channels == 2 || src_channels == 4;
    const bool dst_alpha = dst_channels == 2 || dst_channels == 4;
    if (dst_alpha && k == dst_channels - 1) return src_alpha ? src_channels - 1 : -1;
    return src_channels >= 3 ? k : 0;
}

// One output sample's footprint on a source axis: the source indices it covers and their area weights.
struct Tap {
    int src;
    double weight;
};

std::vector<std::vector<Tap>> area_taps(int src_size, int dst_size) {
    const double scale = double(src_size) / dst_size;
    std::vector<std::vector<Tap>> taps(dst_size);
    for (int o = 0; o < dst_size; ++o) {
        const double lo = o * scale, hi = (o + 1) * scale;
        const int first = int(std::floor(lo)), last = std::min(src_size, int(std::ceil(hi)));
        for (int s = first; s < last; ++s) {
            const double overlap = std::min(hi, s + 1.0) - std::max(lo, double(s));
            if (overlap > 0) taps[o].push_back({s, overlap / scale});
        }
    }
    return taps;
}

}  // namespace

Image to_channels(const Image& image, int channels) {
    if (channels < 1 || channels > 4) throw Error("to_channels: channel count must be 1 to 4");
    Image out(image.width, image.height, channels);
    const std::size_t n = std::size_t(image.width) * image.height;
    for (int k = 0; k < channels; ++k) {
        const int s = source_channel(image.channels, channels, k);
        for (std::size_t p = 0; p < n; ++p)
            out.pixels[p * channels + k] = s < 0 ? 1.0f : image.pixels[p * image.channels + s];
    }
    return out;
}

Image resize_area(const Image& image, int new_width, int new_height) {
    if (image.empty() || new_width < 1 || new_height < 1)
        throw Error("resize_area: empty image or target size " + std::to_string(new_width) + "x" +
                    std::to_string(new_height));
    const int c = image.channels;
    const auto tx = area_taps(image.width, new_width), ty = area_taps(image.height, new_height);
    // Horizontal pass into a double buffer, then vertical: separable, and exact block means for integer
    // factors.
    std::vector<double> rows(std::size_t(new_width) * image.height * c, 0.0);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < new_width; ++x)
            for (const Tap& t : tx[x])
                for (int k = 0; k < c; ++k)
                    rows[(std::size_t(y) * new_width + x) * c + k] += t.weight * image.at(t.src, y, k);
    Image out(new_width, new_height, c);
    for (int y = 0; y < new_height; ++y)
        for (int x = 0; x < new_width; ++x)
            for (int k = 0; k < c; ++k) {
                double sum = 0.0;
                for (const Tap& t : ty[y])
                    sum += t.weight * rows[(std::size_t(t.src) * new_width + x) * c + k];
                out.at(x, y, k) = float(sum);
            }
    return out;
}

float srgb_to_linear(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float linear) {
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

}  // namespace lumigauss
