#pragma once
// One rasterisation of a relightable model under one environment, carrying every per-surfel quantity the
// relighting tool writes (research/lumigauss_official.md 3 and 7), in 15 colour channels:
//
//     0..2    shadowed colour        albedo * max(T . L, 1e-5)^(1/2.2)  (as render_with_environment, Both)
//     3..5    unshadowed colour      albedo * max(E(n), 1e-5)^(1/2.2)
//     6..8    shadowed intensity     max(T . L, 1e-5)^(1/2.2)  (the official post-gamma "intensity")
//     9..11   unshadowed intensity   max(E(n), 1e-5)^(1/2.2)
//     12..14  albedo                 max(0, Y00 a + 0.5)
//
// plus the rasterizer's alpha, depth and world-normal maps. Black background, as in training.
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

inline constexpr int kRelitChannels = 15;
inline constexpr int kRelitShadowed = 0, kRelitUnshadowed = 3, kRelitIntensityShadowed = 6,
                     kRelitIntensityUnshadowed = 9, kRelitAlbedo = 12;

// Renders one model from many cameras and environments, keeping the per-model albedo and the buffers.
// `sides`: the run's side rule (TrainedRun::side_rule).
class RelitRenderer {
  public:
    explicit RelitRenderer(const SurfelModel& model, RasterBackend backend = RasterBackend::Cpu,
                           const SurfelSideRule& sides = {});
    // The raster output: color has kRelitChannels per pixel (layout above), unclamped.
    const RasterImages<float>& render(const Camera& camera, const ShCoeffs<float>& env);

  private:
    void shade(const ShCoeffs<float>& env, const ViewNormals& normals, SurfelBatch<float>& batch);

    const SurfelModel& model_;
    ModelRenderer renderer_;
    std::vector<float> albedo_;  // 3 per surfel, activated
    SurfelBatch<float> shaded_;  // 6 channels, from shade_surfels
};

// The official shadow image (render_rotate_envmap.py): 1 - clamp(luma(I_unshadowed - I_shadowed), 0, 1000)
// on the rasterised post-gamma intensities, Rec. 709 luma weights. 1 = unshadowed (also the background),
// lower = more shadow; negative values where the difference exceeds 1 (a PNG clamps them to 0).
Image shadow_image(const Image& intensity_unshadowed, const Image& intensity_shadowed);

// The largest value of any of the images, at least 1: the official irradiance visualisation divides by
// the maximum when it exceeds 1.
float display_max(const std::vector<const Image*>& images);
Image divided(const Image& image, float divisor);

// colour + (1 - alpha) * background, per channel (3-channel images).
Image over_background(const Image& colour, const Image& alpha, const Vec3f& background);
// The same over a background image of the same size (3 channels), e.g. the sky (shading/sky_image.h).
Image over_background_image(const Image& colour, const Image& alpha, const Image& background);

}  // namespace lumigauss
