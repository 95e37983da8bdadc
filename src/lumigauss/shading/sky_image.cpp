#include "lumigauss/shading/sky_image.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

constexpr std::size_t kChunk = 4096;  // rays per task and per partial sum of the backward

struct HorizonSines {
    Vec3f up;
    float start, end;
};

HorizonSines horizon_sines(const SkyHorizon& horizon) {
    const auto sine = [](double degrees) {
        return float(std::sin(std::clamp(degrees, 0.0, 90.0) * std::numbers::pi / 180.0));
    };
    const float up_length = length(horizon.up);
    if (!(up_length > 0)) throw Error("sky horizon: the up direction is zero");
    return {(1.0f / up_length) * horizon.up, sine(double(horizon.start_degrees)),
            sine(double(horizon.start_degrees) + double(horizon.fade_degrees))};
}

}  // namespace

Vec3d pixel_ray_direction(const Camera& camera, double x, double y) {
    const Vec3d in_camera{(x + 0.5 - camera.cx) / camera.fx, (y + 0.5 - camera.cy) / camera.fy, 1.0};
    const Vec3d d = transpose(camera.rotation) * in_camera;
    return (1.0 / length(d)) * d;
}

std::vector<Vec3f> pixel_ray_directions(const Camera& camera) {
    std::vector<Vec3f> rays(std::size_t(camera.width) * std::size_t(camera.height));
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y < r.end(); ++y)
            for (int x = 0; x < camera.width; ++x)
                rays[std::size_t(y) * std::size_t(camera.width) + std::size_t(x)] =
                    pixel_ray_direction(camera, x, y).cast<float>();
    });
    return rays;
}

std::vector<float> sky_visibility_image(const Camera& camera, const SkyHorizon& horizon) {
    if (!(horizon.fade_degrees > 0)) return {};
    const HorizonSines h = horizon_sines(horizon);
    const std::vector<Vec3f> rays = pixel_ray_directions(camera);
    std::vector<float> out(rays.size());
    for (std::size_t p = 0; p < rays.size(); ++p) out[p] = sky_visibility(h.up, h.start, h.end, rays[p]);
    return out;
}

Vec3f horizon_ground_colour(const ShCoeffs<float>& env, const SkyHorizon& horizon) {
    const Vec3f a = horizon.ground_albedo;
    if (!(horizon.fade_degrees > 0) || (a.x == 0 && a.y == 0 && a.z == 0)) return {};
    return ground_colour(env, horizon_sines(horizon).up, a);
}

void sky_pixels(std::span<const Vec3f> rays, const ShCoeffs<float>& env, const Sh4Coeffs<float>* residual,
                SkyPixels& out, const SkyHorizon& horizon) {
    out.radiance.resize(3 * rays.size());
    out.colour.resize(3 * rays.size());
    const bool has_horizon = horizon.fade_degrees > 0;
    out.visibility.resize(has_horizon ? rays.size() : 0);
    const HorizonSines h = has_horizon ? horizon_sines(horizon) : HorizonSines{{0, 0, 1}, 0, 0};
    const Vec3f ground = horizon_ground_colour(env, horizon);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, rays.size(), kChunk),
        [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t p = r.begin(); p < r.end(); ++p) {
                const Vec3f radiance = sky_radiance(env, residual, rays[p]);
                const float visible = has_horizon ? sky_visibility(h.up, h.start, h.end, rays[p]) : 1.0f;
                if (has_horizon) out.visibility[p] = visible;
                const Vec3f colour = visible * sky_colour_of(radiance) + (1.0f - visible) * ground;
                for (int c = 0; c < 3; ++c) {
                    out.radiance[3 * p + std::size_t(c)] = radiance[c];
                    out.colour[3 * p + std::size_t(c)] = colour[c];
                }
            }
        });
}

Image sky_image(const Camera& camera, const ShCoeffs<float>& env, const Sh4Coeffs<float>* residual,
                const SkyHorizon& horizon) {
    Image out(camera.width, camera.height, 3);
    SkyPixels sky;
    sky_pixels(pixel_ray_directions(camera), env, residual, sky, horizon);
    out.pixels = std::move(sky.colour);
    return out;
}

SkyGrads sky_pixels_backward(std::span<const Vec3f> rays, const SkyPixels& sky,
                             std::span<const float> g_colour, std::span<const float> g_radiance,
                             bool with_residual) {
    const std::size_t n = rays.size();
    if (sky.radiance.size() != 3 * n || (!g_colour.empty() && g_colour.size() != 3 * n) ||
        (!g_radiance.empty() && g_radiance.size() != 3 * n))
        throw Error("sky_pixels_backward: the sky or a gradient does not fit the rays");
    if (!sky.visibility.empty() && sky.visibility.size() != n)
        throw Error("sky_pixels_backward: the sky's visibility does not fit the rays");
    const auto visibility = [&](std::size_t p) {
        return sky.visibility.empty() ? 1.0 : double(sky.visibility[p]);
    };
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<ShCoeffs<double>> env_parts(chunks);
    std::vector<Sh4Coeffs<double>> residual_parts(chunks);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t c = r.begin(); c < r.end(); ++c)
                              for (std::size_t p = c * kChunk; p < std::min(n, (c + 1) * kChunk); ++p) {
                                  Vec3d g{};
                                  for (int k = 0; k < 3; ++k) {
                                      const std::size_t i = 3 * p + std::size_t(k);
                                      double gk = g_radiance.empty() ? 0.0 : double(g_radiance[i]);
                                      if (!g_colour.empty() && g_colour[i] != 0)
                                          gk += double(g_colour[i]) * visibility(p) *
                                                sky_channel_derivative(double(sky.radiance[i]));
                                      g[k] = gk;
                                  }
                                  if (g.x == 0 && g.y == 0 && g.z == 0) continue;
                                  sky_radiance_vjp(rays[p].cast<double>(), g, env_parts[c],
                                                   with_residual ? &residual_parts[c] : nullptr);
                              }
                      });
    ShCoeffs<double> env{};
    Sh4Coeffs<double> residual{};
    for (std::size_t c = 0; c < chunks; ++c) {
        for (int k = 0; k < kShCount; ++k) env.c[k] += env_parts[c].c[k];
        for (int k = 0; k < kSh4Count; ++k) residual.c[k] += residual_parts[c].c[k];
    }
    SkyGrads out;
    for (int k = 0; k < kShCount; ++k) out.env.c[k] = env.c[k].cast<float>();
    for (int k = 0; k < kSh4Count; ++k) out.residual.c[k] = residual.c[k].cast<float>();
    return out;
}

}  // namespace lumigauss
