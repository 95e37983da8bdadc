#pragma once
// The albedo of a scene's ground, read off its surfels: what the sky background draws below the horizon
// where no surfel covers a pixel (SkyHorizon::ground_albedo). Seen from a new viewpoint, the near ground that
// no training photo saw up close is often left uncovered; drawn black, it was the darkest error of the
// novel views, while any ground colour is nearer the truth.
#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

// Per channel, the median of the activated albedo (albedo_activation) over the surfels that face up or
// down (within 30 degrees of `up`: the ground, roofs, steps), each weighted by its opacity times its area,
// so that the many small surfels of a textured patch do not outvote the plaza. 0 when no surfel faces so.
Vec3f ground_albedo(const SurfelModel& model, Vec3f up);

}  // namespace lumigauss
