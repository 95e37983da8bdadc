#include "lumigauss/relight/relit_sky.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/shading/sky_image.h"

namespace lumigauss {
namespace {

// v turned by `radians` about the unit axis (Rodrigues).
Vec3d rotated(Vec3d v, Vec3d axis, double radians) {
    const double c = std::cos(radians), s = std::sin(radians);
    return c * v + s * cross(axis, v) + ((1 - c) * dot(axis, v)) * axis;
}

}  // namespace

Vec3d sample_equirect(const Image& pano, double row, double col) {
    const int w = pano.width, h = pano.height;
    const double r = std::clamp(row - 0.5, 0.0, double(h - 1)), c = col - 0.5;
    const int r0 = int(std::floor(r)), c0 = int(std::floor(c));
    const double fr = r - r0, fc = c - c0;
    const int r1 = std::min(r0 + 1, h - 1);
    const auto at = [&](int y, int x) {
        x = ((x % w) + w) % w;
        Vec3d v;
        for (int k = 0; k < 3; ++k) v[k] = pano.at(x, y, pano.channels >= 3 ? k : 0);
        return v;
    };
    return (1 - fr) * ((1 - fc) * at(r0, c0) + fc * at(r0, c0 + 1)) +
           fr * ((1 - fc) * at(r1, c0) + fc * at(r1, c0 + 1));
}

Image panorama_sky_image(const Camera& camera, const PanoramaSky& sky) {
    Image out(camera.width, camera.height, 3);
    const double radians = -sky.degrees * std::numbers::pi / 180.0;
    const std::vector<float> visibility = sky_visibility_image(camera, sky.horizon);
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) {
            const Vec3d ray = pixel_ray_direction(camera, x, y);
            const Vec3d d = rotated(ray, sky.up, radians);
            const EquirectCoord e =
                direction_to_equirect(d, sky.pixels->width, sky.pixels->height, sky.frame);
            const Vec3d radiance = sample_equirect(*sky.pixels, e.row, e.col);
            const float visible = visibility.empty() ? 1.0f : visibility[std::size_t(y * camera.width + x)];
            for (int c = 0; c < 3; ++c)
                out.at(x, y, c) = visible * float(sky_channel(sky.factor[c] * radiance[c])) +
                                  (1.0f - visible) * sky.ground[c];
        }
    return out;
}

}  // namespace lumigauss
