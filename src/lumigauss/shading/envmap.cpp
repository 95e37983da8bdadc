#include "lumigauss/shading/envmap.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "lumigauss/shading/irradiance.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

constexpr double kPi = std::numbers::pi;

// The RGB radiance of pixel (x, y): gray panoramas (1 or 2 channels) replicate channel 0.
Vec3d pixel_rgb(const Image& pano, int x, int y) {
    const Vec3d v = pano.channels >= 3 ? Vec3d{pano.at(x, y, 0), pano.at(x, y, 1), pano.at(x, y, 2)}
                                       : Vec3d{pano.at(x, y, 0), pano.at(x, y, 0), pano.at(x, y, 0)};
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        throw Error("panorama pixel (row " + std::to_string(y) + ", col " + std::to_string(x) +
                    ") is not finite; fix or clamp the image before using it as lighting");
    return v;
}

void check_panorama(const Image& pano, const char* what) {
    if (pano.empty() || pano.width <= 0 || pano.height <= 0 || pano.channels <= 0)
        throw Error(std::string(what) + ": the panorama is empty");
}

// Calls f(x, y, world direction, solid angle) for every pixel, rows outermost.
template <typename F>
void for_each_pixel_direction(int width, int height, const Mat3d& frame, F&& f) {
    for (int y = 0; y < height; ++y) {
        const double d_omega = equirect_pixel_solid_angle(y, width, height);
        for (int x = 0; x < width; ++x) f(x, y, equirect_direction(y, x, width, height, frame), d_omega);
    }
}

// A 3-channel panorama whose pixel value is value(world direction).
template <typename F>
Image render_panorama(int width, int height, const Mat3d& frame, F&& value) {
    if (width <= 0 || height <= 0) throw Error("panorama size must be positive");
    Image out(width, height, 3);
    for_each_pixel_direction(width, height, frame, [&](int x, int y, Vec3d d, double) {
        const Vec3d v = value(d);
        for (int c = 0; c < 3; ++c) out.at(x, y, c) = static_cast<float>(v[c]);
    });
    return out;
}

}  // namespace

Vec3d equirect_direction(double row, double col, int width, int height, const Mat3d& frame) {
    const double theta = kPi * (row + 0.5) / height;
    const double phi = 2 * kPi * (0.5 - (col + 0.5) / width);
    const Vec3d d{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
    return frame * d;
}

EquirectCoord direction_to_equirect(Vec3d dir, int width, int height, const Mat3d& frame) {
    const Vec3d d = normalize(transpose(frame) * dir);  // frame is a rotation: its inverse is its transpose
    const double theta = std::acos(std::clamp(d.z, -1.0, 1.0));
    const double phi = std::atan2(d.y, d.x);  // (-pi, pi]
    double col = width * (0.5 - phi / (2 * kPi)) - 0.5;
    if (col >= width - 0.5) col -= width;  // keep the seam on the left edge
    return {theta * height / kPi - 0.5, col};
}

double equirect_pixel_solid_angle(int row, int width, int height) {
    const double theta = kPi * (row + 0.5) / height, half = kPi / (2 * height);
    return (2 * kPi / width) * (std::cos(theta - half) - std::cos(theta + half));
}

ShCoeffs<double> project_panorama_to_sh(const Image& pano, const Mat3d& frame) {
    check_panorama(pano, "project_panorama_to_sh");
    ShCoeffs<double> sh;
    for_each_pixel_direction(pano.width, pano.height, frame, [&](int x, int y, Vec3d d, double d_omega) {
        double basis[kShCount];
        sh_basis(d, basis);
        const Vec3d weighted = d_omega * pixel_rgb(pano, x, y);
        for (int k = 0; k < kShCount; ++k) sh.c[k] += basis[k] * weighted;
    });
    return sh;
}

Image render_sh_panorama(const ShCoeffs<double>& sh, int width, int height, const Mat3d& frame) {
    return render_panorama(width, height, frame, [&](Vec3d d) { return eval_sh(sh, d); });
}

Image render_irradiance_panorama(const ShCoeffs<double>& sh, int width, int height, const Mat3d& frame) {
    return render_panorama(width, height, frame, [&](Vec3d n) { return irradiance(sh, n); });
}

Vec3d panorama_irradiance(const Image& pano, Vec3d normal, const Mat3d& frame) {
    check_panorama(pano, "panorama_irradiance");
    const Vec3d n = normalize(normal);
    Vec3d e{};
    for_each_pixel_direction(pano.width, pano.height, frame, [&](int x, int y, Vec3d d, double d_omega) {
        const double cosine = dot(n, d);
        if (cosine > 0) e += (cosine * d_omega) * pixel_rgb(pano, x, y);
    });
    return e;
}

}  // namespace lumigauss
