#pragma once
// The synthetic photos' renderer: one primary ray per sample (2 x 2 jittered-stratified samples per pixel
// by default) and one shadow ray towards the sun. Shading of a hit with albedo rho and normal n:
//   L = rho / pi * (E_sky(n) + [sun visible] * sun_power * max(0, n.s)),
// E_sky the Ramamoorthi-Hanrahan irradiance of the sky SH, with the sky NOT occluded (no ambient occlusion,
// no interreflections): shadows are the sun's, hard, traced against every primitive including pedestrians.
// A ray that misses shows the sky radiance (sky SH clamped at 0, plus the sun disc).
//
// Deterministic: each pixel's jitter comes from a stream keyed by (seed, image, pixel), so the result does
// not depend on the number of threads (rows run in parallel with oneTBB).
#include <cstdint>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/synth/sky.h"
#include "lumigauss/synth/world.h"

namespace lumigauss::synth {

struct RenderSettings {
    int samples_per_side = 2;  // samples_per_side^2 samples per pixel
    std::uint64_t seed = 1;
    int image_index = 0;
};

// Per-pixel means over the samples (row-major, pixel (x, y) at y * width + x).
struct ViewBuffers {
    int width = 0, height = 0;
    std::vector<Vec3d> radiance;      // linear radiance (no exposure)
    std::vector<Vec3d> albedo;        // 0 where the sample saw the sky
    std::vector<Vec3d> normal;        // world-space unit normals averaged; 0 for sky samples
    std::vector<double> coverage;     // fraction of samples on any geometry
    std::vector<double> transient;    // fraction of samples on a pedestrian
    std::vector<double> sun_visible;  // fraction of samples lit by the sun (facing it and unshadowed)
    std::vector<double> landmark;  // fraction of samples on the landmark (not the ground, not a pedestrian)
};

ViewBuffers render_view(const World& world, const LightCondition& light, const Camera& camera,
                        const RenderSettings& settings);

// Shading of one surface point (the formula above), exposed for tests.
Vec3d shade_point(const LightCondition& light, Vec3d albedo, Vec3d normal, bool sun_visible);

// 8-bit value of a linear radiance under an exposure: round(255 * srgb(clip(exposure * radiance, 0, 1))).
int encode_pixel(double exposure, double radiance);

}  // namespace lumigauss::synth
