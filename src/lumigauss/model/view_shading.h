#pragma once
// Shading of every surfel of the model for one photo, before rasterisation (the official
// `compute_gaussian_rgb`, research/lumigauss_official.md 2.1 and 3). Its backward, into the raw parameters
// and the photo's environment SH, is training's (train/view_shading_backward.h).
//
// Per surfel: the unit normal n = R(q)[:,2] is flipped to the side the camera sees (shading/surfel_side.h:
// the side facing the camera, multiplier +1 when -(W n) . p_view >= 0, as the official
// compute_normal_world_space; with a run's grazing rule, the upper side of a level surfel seen at a grazing
// angle); the multiplier also picks the transfer set (positive side when +1). The per-surfel maths is in
// shading/surfel_shading.h; this file runs it over the model (in parallel, deterministic) and chains the
// normal gradient to the raw quaternion.
#include <cstdint>
#include <span>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/model/surfel_model.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/surfel_side.h"

namespace lumigauss {

// Which colours the batch carries: unshadowed RGB, shadowed RGB, or both in the 6-channel layout of
// surfel_shading.h (shadowed in 0..2, unshadowed in 3..5) so that one rasterisation serves both losses.
enum class ShadingMode { Unshadowed, Shadowed, Both };
int shading_channels(ShadingMode mode);
inline bool uses_unshadowed(ShadingMode mode) {
    return mode != ShadingMode::Shadowed;
}
inline bool uses_shadowed(ShadingMode mode) {
    return mode != ShadingMode::Unshadowed;
}

// The per-view facts of every surfel that shading, the physical losses and their backward share.
struct ViewNormals {
    std::vector<Vec3f> normal;                // unit normal of the side seen (camera-facing but for the rule)
    std::vector<std::uint8_t> positive_side;  // 1: multiplier +1 (positive transfer set), 0: -1
};

// Normals and sides of every surfel as seen from `camera` under `rule` (the run's; {} = official).
void compute_view_normals(const SurfelModel& model, const Camera& camera, ViewNormals& out,
                          const SurfelSideRule& rule = {});

// Writes batch.channels and batch.colors (the geometry is left to SurfelModel::activated). `env` is the
// photo's environment radiance SH as used for this render (training noise included).
void shade_surfels(const SurfelModel& model, const ShCoeffs<float>& env, ShadingMode mode,
                   const ViewNormals& normals, SurfelBatch<float>& batch);

}  // namespace lumigauss
