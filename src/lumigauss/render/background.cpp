#include "lumigauss/render/background.h"

#include <string>

#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

template <typename T>
void check_sizes(const RasterImages<T>& images, std::size_t background, int first, const char* who) {
    const std::size_t pixels = std::size_t(images.width) * std::size_t(images.height);
    if (background != 3 * pixels || first < 0 || first + 3 > images.channels ||
        images.alpha.size() != pixels || images.color.size() != pixels * std::size_t(images.channels))
        throw Error(std::string(who) + ": the background, the channels or the maps do not fit the image");
}

}  // namespace

template <typename T>
void composite_background(RasterImages<T>& images, std::span<const T> background, int first) {
    check_sizes(images, background.size(), first, "composite_background");
    const auto channels = std::size_t(images.channels);
    for (std::size_t p = 0; p < images.alpha.size(); ++p) {
        const T transmittance = T(1) - images.alpha[p];
        for (std::size_t c = 0; c < 3; ++c)
            images.color[p * channels + std::size_t(first) + c] += transmittance * background[3 * p + c];
    }
}

template <typename T>
void composite_background_backward(const RasterImages<T>& images, std::span<const T> background, int first,
                                   RasterImageGrads<T>& grads, std::span<T> g_background) {
    check_sizes(images, background.size(), first, "composite_background_backward");
    const std::size_t pixels = images.alpha.size();
    if (grads.color.size() != images.color.size() || g_background.size() != 3 * pixels)
        throw Error("composite_background_backward: gradient buffers do not fit the image");
    if (grads.alpha.empty()) grads.alpha.assign(pixels, T(0));
    const auto channels = std::size_t(images.channels);
    for (std::size_t p = 0; p < pixels; ++p) {
        const T transmittance = T(1) - images.alpha[p];
        T g_alpha = 0;
        for (std::size_t c = 0; c < 3; ++c) {
            const T g = grads.color[p * channels + std::size_t(first) + c];
            g_background[3 * p + c] += transmittance * g;
            g_alpha -= background[3 * p + c] * g;
        }
        grads.alpha[p] += g_alpha;
    }
}

template void composite_background<float>(RasterImages<float>&, std::span<const float>, int);
template void composite_background<double>(RasterImages<double>&, std::span<const double>, int);
template void composite_background_backward<float>(const RasterImages<float>&, std::span<const float>, int,
                                                   RasterImageGrads<float>&, std::span<float>);
template void composite_background_backward<double>(const RasterImages<double>&, std::span<const double>, int,
                                                    RasterImageGrads<double>&, std::span<double>);

}  // namespace lumigauss
