#pragma once
// Shading of every surfel of the model for one photo, before rasterisation (the official
// `compute_gaussian_rgb`, research/lumigauss_official.md 2.1 and 3), and its backward into the model's raw
// parameters and the photo's environment SH.
//
// Per surfel: the unit normal n = R(q)[:,2] is flipped to face the camera (multiplier +1 when
// -(W n) . p_view >= 0, as the official compute_normal_world_space); the multiplier also picks the transfer
// set (positive side when +1). The per-surfel maths is in shading/surfel_shading.h; this file runs it over
// the model (in parallel, deterministic) and chains the normal gradient to the raw quaternion.
#include <cstdint>
#include <span>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/scene/gaussian_model.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// Which colours the batch carries: unshadowed RGB, shadowed RGB, or both in the 6-channel layout of
// surfel_shading.h (shadowed in 0..2, unshadowed in 3..5) so that one rasterisation serves both losses.
enum class ShadingMode { Unshadowed, Shadowed, Both };
int shading_channels(ShadingMode mode);

// The per-view facts of every surfel that shading, the physical losses and their backward share.
struct ViewNormals {
    std::vector<Vec3f> normal;                // camera-flipped unit normal
    std::vector<std::uint8_t> positive_side;  // 1: multiplier +1 (positive transfer set), 0: -1
};

// Normals and sides of every surfel as seen from `camera`.
void compute_view_normals(const GaussianModel& model, const Camera& camera, ViewNormals& out);

// Writes batch.channels and batch.colors (the geometry is left to GaussianModel::activated). `env` is the
// photo's environment radiance SH as used for this render (training noise included).
void shade_surfels(const GaussianModel& model, const ShCoeffs<float>& env, ShadingMode mode,
                   const ViewNormals& normals, SurfelBatch<float>& batch);

// Backward of shade_surfels: `g_colors` holds dL/dcolour, shading_channels(mode) per surfel. Adds the
// gradients of the raw albedo, of channel 0 of the used transfer sets (only in modes with shadowing) and,
// through the normal, of the raw quaternion (only in modes with the unshadowed term) into the model's
// gradient buffers; returns dL/denv. The reduction over surfels runs in fixed chunks summed in order, so
// the result does not depend on thread scheduling.
ShCoeffs<float> shade_surfels_backward(GaussianModel& model, const ShCoeffs<float>& env, ShadingMode mode,
                                       const ViewNormals& normals, std::span<const float> g_colors);

// Renders the model from `camera` under the environment `env` (no training noise) in the given mode, with a
// black background as in training: colour (3 or 6 channels), alpha, depth and normal maps.
RasterImages<float> render_with_environment(const GaussianModel& model, const Camera& camera,
                                            const ShCoeffs<float>& env, ShadingMode mode);

}  // namespace lumigauss
