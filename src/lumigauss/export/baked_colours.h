#pragma once
// One colour per surfel under one environment, for the formats that hold a single colour per splat
// (ply-3dgs, splat). LumiGauss shading is view-dependent only through the two-sided surfel: the side facing
// the camera picks the normal (unshadowed) or the transfer set (shadowed) (model/view_shading.h). A
// one-colour splat cannot switch sides, so the bake always shades the POSITIVE side: the unit normal
// +R(q)[:,2] and the positive transfer set, i.e. exactly what render_with_environment gives for a camera
// that sees the surfel's +normal side. Surfels seen from their back side get the front side's colour.
//   shadowed:    albedo * max(T+ . L, 1e-5)^(1/2.2)         (the full LumiGauss colour; the default)
//   unshadowed:  albedo * max(E(+n), 1e-5)^(1/2.2)
// Then clamped to [0, 1] (display range: the model's colours are already gamma-encoded).
#include <string>
#include <vector>

#include "lumigauss/model/surfel_model.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

enum class BakeShading { Shadowed, Unshadowed };

// "shadowed" / "unshadowed" -> the mode; throws Error on anything else.
BakeShading parse_bake_shading(const std::string& text);

// 3 floats per surfel in [0, 1], computed in float exactly as shade_surfels does for the positive side.
std::vector<float> bake_surfel_colours(const SurfelModel& model, const ShCoeffs<float>& env,
                                       BakeShading shading);

}  // namespace lumigauss
