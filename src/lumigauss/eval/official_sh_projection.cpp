#include "lumigauss/eval/official_sh_projection.h"

#include <cmath>
#include <filesystem>
#include <numbers>

#include "lumigauss/eval/opencv_resize.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

constexpr double kPi = std::numbers::pi;

std::string size_text(const Image& im) {
    return std::to_string(im.width) + " x " + std::to_string(im.height);
}

}  // namespace

Vec3d official_panorama_direction(int row, int col, int width) {
    const int height = width / 2;
    const double theta = kPi * row / height, phi = 2 * kPi * col / width;
    return {-std::sin(theta) * std::cos(phi), -std::sin(theta) * std::sin(phi), std::cos(theta)};
}

double official_pixel_solid_angle(int row, int width) {
    const int height = width / 2;
    const double ts = kPi * (1.0 - (row + 0.5) / height), half = kPi / (2.0 * height);
    return (2 * kPi / width) * (std::cos(ts - half) - std::cos(ts + half));
}

ShCoeffs<double> official_project_panorama(const Image& panorama) {
    if (panorama.empty() || panorama.width <= 0 || panorama.height <= 0) throw Error("the panorama is empty");
    const Image pano =
        panorama.width > kOfficialPanoramaMaxWidth
            ? resize_cubic_opencv(panorama, kOfficialPanoramaMaxWidth, kOfficialPanoramaMaxWidth / 2)
            : panorama;
    if (pano.height != pano.width / 2)
        throw Error(
            "the panorama is " + size_text(pano) +
            " pixels; the official projection needs a 2:1 equirectangular image (height = width / 2)");
    const bool gray = pano.channels < 3;
    ShCoeffs<double> sh;
    for (int row = 0; row < pano.height; ++row) {
        const double d_omega = official_pixel_solid_angle(row, pano.width);
        for (int col = 0; col < pano.width; ++col) {
            Vec3d v;
            for (int c = 0; c < 3; ++c) v[c] = pano.at(col, row, gray ? 0 : c);
            if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                throw Error("pixel (row " + std::to_string(row) + ", col " + std::to_string(col) +
                            ") is not finite");
            double y[kShCount];
            sh_basis(official_panorama_direction(row, col, pano.width), y);
            for (int k = 0; k < kShCount; ++k) sh.c[k] += (y[k] * d_omega) * v;
        }
    }
    return sh;
}

OfficialEnvironment official_environment_sh(const std::string& path, double threshold, double scale) {
    if (!(scale > 0) || !std::isfinite(scale) || !std::isfinite(threshold))
        fail_in_file(path, "the fake-HDR threshold must be finite and the scale positive");
    if (!std::filesystem::exists(path)) fail_in_file(path, "missing (an environment panorama)");
    Image pano = read_image(path);
    OfficialEnvironment env;
    env.width = pano.width, env.height = pano.height;
    if (is_ldr_panorama(path)) env.boosted = fake_hdr_boost(pano, threshold, scale);
    try {
        env.sh = official_project_panorama(pano);
    } catch (const Error& e) {
        fail_in_file(path, e.what());
    }
    return env;
}

}  // namespace lumigauss
