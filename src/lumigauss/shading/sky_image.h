#pragma once
// The sky a camera sees: every pixel's world-space viewing ray and the sky's radiance and display colour
// along it (sky_colour.h), drawn behind the surfels so that no surfel has to paint the sky
// (research/sky_and_floaters.md 3.2). Per-pixel arrays are row-major, 3 floats per pixel.
#include <span>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss {

// The unit world direction of the ray through the centre of pixel (x, y): R^T K^-1 (x + 0.5, y + 0.5, 1).
Vec3d pixel_ray_direction(const Camera& camera, double x, double y);

// Unit ray directions of every pixel centre, row-major.
std::vector<Vec3f> pixel_ray_directions(const Camera& camera);

// Where the sky ends below: see sky_visibility (sky_colour.h). The default has no horizon.
struct SkyHorizon {
    Vec3f up{0, 0, 1};
    float start_degrees = 0;  // below the horizon, where the sky starts to fade
    float fade_degrees = 0;   // over how many degrees it fades to 0; 0: the environment is drawn everywhere
    // Where the sky has faded, the ground of this albedo is drawn (ground_colour, sky_colour.h); 0: black.
    Vec3f ground_albedo{0, 0, 0};
};

// The display colour of the horizon's ground under `env` (0 without a horizon or a ground albedo).
Vec3f horizon_ground_colour(const ShCoeffs<float>& env, const SkyHorizon& horizon);

// The sky along every ray: radiance (environment + residual, when given), display colour times the ray's
// visibility (sky_visibility) plus the horizon's ground times the rest, and that visibility (empty when
// there is no horizon). The ground takes the light as it is: the backward passes nothing through it.
struct SkyPixels {
    std::vector<float> radiance, colour, visibility;
};
void sky_pixels(std::span<const Vec3f> rays, const ShCoeffs<float>& env, const Sh4Coeffs<float>* residual,
                SkyPixels& out, const SkyHorizon& horizon = {});

// Every pixel's sky_visibility under `horizon`, row-major; empty when it has no fade (all visible).
std::vector<float> sky_visibility_image(const Camera& camera, const SkyHorizon& horizon);

// The sky colour of a whole view as an image.
Image sky_image(const Camera& camera, const ShCoeffs<float>& env, const Sh4Coeffs<float>* residual = nullptr,
                const SkyHorizon& horizon = {});

struct SkyGrads {
    ShCoeffs<float> env;
    Sh4Coeffs<float> residual;
};

// Backward of sky_pixels: dL/denv and (with_residual) dL/dresidual for dL/dcolour = g_colour and
// dL/dradiance = g_radiance (3 per ray each; either may be empty). Summed in fixed chunks in order, so the
// result does not depend on the threads.
SkyGrads sky_pixels_backward(std::span<const Vec3f> rays, const SkyPixels& sky,
                             std::span<const float> g_colour, std::span<const float> g_radiance,
                             bool with_residual = true);

}  // namespace lumigauss
