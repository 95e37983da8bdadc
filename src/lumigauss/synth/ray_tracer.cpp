#include "lumigauss/synth/ray_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumigauss/io/image.h"
#include "lumigauss/synth/camera_paths.h"
#include "lumigauss/synth/rng.h"

namespace lumigauss::synth {

namespace {

struct Sample {
    Vec3d radiance, albedo, normal;
    bool geometry = false, transient = false, sun_visible = false, landmark = false;
};

Sample trace_sample(const World& world, const LightCondition& light, const Ray& ray) {
    Sample s;
    const auto hit = trace(world, ray);
    if (!hit) {
        s.radiance = sky_radiance(light, ray.dir);
        return s;
    }
    const Primitive& prim = world.prims[hit->prim];
    const Vec3d p = ray.origin + hit->hit.t * ray.dir;
    const Vec3d n = hit->hit.normal;
    s.geometry = true;
    s.transient = prim.transient;
    s.landmark = !prim.transient && hit->prim != 0;  // the landmark's world holds the ground first
    s.normal = n;
    s.albedo = albedo_at(world.materials[prim.material], hit->hit.u, hit->hit.v);
    s.sun_visible = dot(n, light.sun_dir) > 0 && !occluded(world, Ray{p + kRayEpsilon * n, light.sun_dir});
    s.radiance = shade_point(light, s.albedo, n, s.sun_visible);
    return s;
}

}  // namespace

Vec3d shade_point(const LightCondition& light, Vec3d albedo, Vec3d normal, bool sun_visible) {
    Vec3d e = sky_irradiance(light, normal);
    if (sun_visible) e += sun_irradiance(light, normal);
    return hadamard(albedo, e) / std::numbers::pi;
}

int encode_pixel(double exposure, double radiance) {
    const double v = std::clamp(exposure * radiance, 0.0, 1.0);
    return int(std::lround(255.0 * double(linear_to_srgb(float(v)))));
}

ViewBuffers render_view(const World& world, const LightCondition& light, const Camera& camera,
                        const RenderSettings& settings) {
    const int w = camera.width, h = camera.height, n = settings.samples_per_side;
    ViewBuffers b;
    b.width = w, b.height = h;
    const std::size_t count = std::size_t(w) * h;
    b.radiance.resize(count), b.albedo.resize(count), b.normal.resize(count);
    b.coverage.resize(count), b.transient.resize(count), b.sun_visible.resize(count),
        b.landmark.resize(count);
    const double inv = 1.0 / (n * n);
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < w; ++x) {
                Rng rng(settings.seed, Stream::kPixel, std::uint64_t(settings.image_index),
                        std::uint64_t(y) * std::uint64_t(w) + std::uint64_t(x));
                const std::size_t i = std::size_t(y) * w + x;
                Vec3d rad, alb, nor;
                double cov = 0, tra = 0, sun = 0, obj = 0;
                for (int sy = 0; sy < n; ++sy)
                    for (int sx = 0; sx < n; ++sx) {
                        const double px = x + (sx + rng.uniform()) / n, py = y + (sy + rng.uniform()) / n;
                        const Sample s = trace_sample(world, light, camera_ray(camera, px, py));
                        rad += s.radiance, alb += s.albedo, nor += s.normal;
                        cov += s.geometry, tra += s.transient, sun += s.sun_visible, obj += s.landmark;
                    }
                b.radiance[i] = inv * rad, b.albedo[i] = inv * alb, b.normal[i] = inv * nor;
                b.coverage[i] = inv * cov, b.transient[i] = inv * tra, b.sun_visible[i] = inv * sun;
                b.landmark[i] = inv * obj;
            }
    });
    return b;
}

}  // namespace lumigauss::synth
