#pragma once
// Turning a model's world before it is exported, so that it stands upright in viewers that assume an up
// axis: SPZ is y-up by definition, and `export --orient` turns ply-3dgs and splat files for y-up viewers or
// for the y-down (COLMAP, Inria 3DGS) convention most splat viewers assume. The baked colours do not depend
// on the frame; the view-dependent SH and the side a camera sees are computed on the turned model with the
// turned cameras.
#include <span>
#include <string>
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

// The smallest rotation taking the direction `from` to the direction `to` (180 degrees about an axis
// perpendicular to both when they are opposite).
Mat3d rotation_taking(Vec3d from, Vec3d to);

struct TurnedWorld {
    SurfelModel model;           // positions R p, rotations R R(q), everything else as it was
    std::vector<Vec3d> cameras;  // R c
};
TurnedWorld turn_world(const SurfelModel& model, std::span<const Vec3d> cameras, const Mat3d& R);

// `--orient`: "none" (the world as trained), "y-up" (up turned to +y) or "y-down" (up turned to -y). Throws
// Error on anything else.
enum class ExportOrientation { None, YUp, YDown };
ExportOrientation parse_export_orientation(const std::string& text);
// The rotation of an orientation for the world's `up` (identity for None).
Mat3d orientation_rotation(ExportOrientation orientation, Vec3d up);

}  // namespace lumigauss
