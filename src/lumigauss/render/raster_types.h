#pragma once
// Inputs and outputs of the surfel rasterizer (any backend, render/rasterizer.h), as structures of arrays.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/render/surfel_kernel.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

// Colour channels per surfel every backend handles (RGB, shadowed + unshadowed RGB, and some room).
inline constexpr int kMaxChannels = 16;

// Activated surfel parameters for one render: linear scales, opacity in [0, 1], any number of colour
// channels (3 for RGB; 6 when shadowed and unshadowed shading are rendered in one pass).
template <typename T>
struct SurfelBatch {
    int channels = 3;
    std::vector<T> means;      // 3 per surfel
    std::vector<T> quats;      // 4 per surfel, w x y z, not necessarily normalised
    std::vector<T> scales;     // 2 per surfel: s_u, s_v
    std::vector<T> opacities;  // 1 per surfel
    std::vector<T> colors;     // `channels` per surfel

    std::size_t size() const { return opacities.size(); }
    void resize(std::size_t n) {
        means.resize(3 * n), quats.resize(4 * n), scales.resize(2 * n), opacities.resize(n);
        colors.resize(std::size_t(channels) * n);
    }
    raster::SurfelGeometry<T> geometry(std::size_t i) const {
        return {{means[3 * i], means[3 * i + 1], means[3 * i + 2]},
                {quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]},
                scales[2 * i],
                scales[2 * i + 1]};
    }
};

// Throws Error when a batch has a channel count no backend handles or arrays that disagree with its
// surfel count and channels (a batch assembled by hand): every backend checks before it reads them.
template <typename T>
void check_surfel_batch(const SurfelBatch<T>& s) {
    if (s.channels < 1 || s.channels > kMaxChannels)
        throw Error("the rasterizer supports 1 to " + std::to_string(kMaxChannels) +
                    " colour channels, not " + std::to_string(s.channels));
    const std::size_t n = s.size();
    const auto expect = [&](const std::vector<T>& v, std::size_t per_surfel, const char* what) {
        if (v.size() != per_surfel * n)
            throw Error(std::string("surfel batch: ") + what + " has " + std::to_string(v.size()) +
                        " values for " + std::to_string(n) + " surfels (" + std::to_string(per_surfel) +
                        " each)");
    };
    expect(s.means, 3, "means");
    expect(s.quats, 4, "quats");
    expect(s.scales, 2, "scales");
    expect(s.colors, std::size_t(s.channels), "colors");
}

// Every map the rasterizer writes, row-major, `width * height` pixels.
template <typename T>
struct RasterImages {
    int width = 0, height = 0, channels = 0;
    std::vector<T> color;         // `channels` per pixel, background included
    std::vector<T> alpha;         // 1 - final transmittance
    std::vector<T> depth;         // sum of w_i z_i (divide by alpha for the expected depth)
    std::vector<T> median_depth;  // depth where the transmittance crosses 0.5
    std::vector<T> normal;        // 3 per pixel: sum of w_i n_i, world space, camera-facing
    std::vector<T> distortion;    // sum_{j<i} w_i w_j (m_i - m_j)^2 on mapped depth m
};

// dL/d(map) for each map; an empty vector means zero.
template <typename T>
using RasterImageGrads = RasterImages<T>;

template <typename T>
struct SurfelGrads {
    std::vector<T> means, quats, scales, opacities, colors;
    std::vector<T> mean2d;  // 2 per surfel: dL/d(screen translation of the projected centre), pixels
};

template <typename T>
struct RasterSettings {
    std::vector<T> background;  // `channels` values; empty = black
};

template <typename T>
raster::PinholeView<T> pinhole_view(const Camera& camera) {
    return {camera.rotation.cast<T>(),
            camera.translation.cast<T>(),
            T(camera.fx),
            T(camera.fy),
            T(camera.cx),
            T(camera.cy),
            camera.width,
            camera.height};
}

}  // namespace lumigauss
