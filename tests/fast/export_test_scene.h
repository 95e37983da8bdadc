#pragma once
// The scene the export tests render exported files in: surfels of random orientation in a cube (about half
// show each side to any camera), cameras all around it, a light with a strong direction, and PSNR in the
// display range.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "lumigauss/cameras/orbit.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"

namespace lumigauss::export_test {

// `count` surfels in the cube [-1, 1]^3 with random orientations: about half show each side to any camera.
inline GaussianModel cube_model(std::uint64_t seed, std::size_t count = 120) {
    auto raw = relight_test::random_raw(lumigauss::testing::test_camera(), seed, count);
    std::mt19937_64 rng(seed + 1);
    for (std::size_t i = 0; i < count; ++i) {
        for (int k = 0; k < 3; ++k)
            raw[int(ModelParam::Xyz)][3 * i + std::size_t(k)] = float(relight_test::uniform(rng));
        for (int k = 0; k < 4; ++k)
            raw[int(ModelParam::Rotation)][4 * i + std::size_t(k)] = float(relight_test::uniform(rng));
        for (int k = 0; k < 2; ++k)
            raw[int(ModelParam::Scaling)][2 * i + std::size_t(k)] =
                float(relight_test::uniform(rng, -2.2, -1.4));
        raw[int(ModelParam::Opacity)][i] = float(relight_test::uniform(rng, 0.0, 3.0));
        // The back sides mostly in shadow: their transfer's DC at a third of the front's.
        raw[int(ModelParam::TransferNegative)][i * kTransferStored] =
            float(relight_test::uniform(rng, 0.2, 0.5));
    }
    return GaussianModel::from_raw(std::move(raw), 1.0);
}

// Cameras around the cube: six on a tilted ring and one above, 3.5 units from the centre.
inline std::vector<Camera> ring_cameras() {
    const Camera intrinsics = lumigauss::testing::test_camera(64, 48);
    std::vector<Camera> cams;
    for (int k = 0; k < 6; ++k) {
        const double a = 2 * 3.141592653589793 * k / 6;
        cams.push_back(look_at(intrinsics, {3.5 * std::cos(a), 3.5 * std::sin(a), std::cos(3 * a)}, {0, 0, 0},
                               {0, 0, 1}));
    }
    cams.push_back(look_at(intrinsics, {0.3, 0.2, 3.5}, {0, 0, 0}, {0, 1, 0}));
    return cams;
}

// A moderate environment with a strong direction (band 1): colours stay mostly below 1, and the two sides
// of a surfel differ in unshadowed shading too.
inline ShCoeffs<float> moderate_env() {
    ShCoeffs<double> sh = relight_test::bright_sh(11);
    for (int k = 0; k < kShCount; ++k) sh.c[k] = sh.c[k] * (k == 0 ? 0.5 : k < 4 ? 0.6 : 0.15);
    return sh.cast<float>();
}

// PSNR of two colour maps, both clamped to the display range [0, 1].
inline double display_psnr(const std::vector<float>& a, const std::vector<float>& b) {
    double se = 0;
    for (std::size_t p = 0; p < a.size(); ++p) {
        const double d = std::clamp(double(a[p]), 0.0, 1.0) - std::clamp(double(b[p]), 0.0, 1.0);
        se += d * d;
    }
    return 10 * std::log10(double(a.size()) / std::max(se, 1e-30));
}

}  // namespace lumigauss::export_test
