#pragma once
// The colours of a relightable model under one environment, for the formats that hold no lighting
// (ply-3dgs, splat). LumiGauss shading depends on the view only through the two-sided surfel: the side that
// faces the camera picks the normal (unshadowed) or the transfer set (shadowed) (model/view_shading.h). Both
// sides are baked here:
//   shadowed:    albedo * max(T_side . L, 1e-5)^(1/2.2)     (the full LumiGauss colour; the default)
//   unshadowed:  albedo * max(E(+-n), 1e-5)^(1/2.2)
// The model's colours are already display (gamma-encoded) values; they are not clamped here: a 3DGS renderer
// blends them as they are and clamps the pixel, as LumiGauss does. The training leaves the sign of a surfel's
// normal arbitrary (both sides shade): on the synthetic scenes half the surfels or more show their NEGATIVE
// side to the training cameras, which is why one colour per surfel cannot be the positive side's.
#include <span>
#include <string>
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

enum class BakeShading { Shadowed, Unshadowed };

// "shadowed" / "unshadowed" -> the mode; throws Error on anything else.
BakeShading parse_bake_shading(const std::string& text);

// 3 floats per surfel for each side, computed in float exactly as shade_surfels does.
struct SurfelSides {
    std::vector<float> positive;  // seen by a camera on the +normal side
    std::vector<float> negative;  // seen from behind
};
SurfelSides bake_surfel_sides(const SurfelModel& model, const ShCoeffs<float>& env, BakeShading shading);

// One colour per surfel for the one-colour formats (.splat, a degree-0 PLY): the side that `cameras` (camera
// centres; the training photos) see more, each camera weighted by |cos| between the surfel's normal and its
// direction (a surfel's projected area). Without cameras, the positive side.
std::vector<float> seen_side_colours(const SurfelModel& model, const SurfelSides& sides,
                                     std::span<const Vec3d> cameras);

}  // namespace lumigauss
