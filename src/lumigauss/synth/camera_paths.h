#pragma once
// Tourist-like viewpoints of a landmark: from the front and the sides (never from behind), at eye height
// or from a raised spot, near or far, with a 28-42 mm (35 mm-equivalent) lens and a slight roll.
#include <cstdint>

#include "lumigauss/io/camera.h"
#include "lumigauss/synth/world.h"

namespace lumigauss::synth {

// The camera of photo `view_index` (train and test photos draw from the same distribution, with
// different indices, so test photos are novel views).
Camera make_tourist_camera(const Landmark& landmark, int width, int height, std::uint64_t seed,
                           int view_index);

// World-to-camera rotation (OpenCV axes: x right, y down, z forward) of a camera at `eye` looking at
// `target` with +Z up in the image, then rolled by `roll` radians about the viewing axis.
Mat3d look_at_rotation(Vec3d eye, Vec3d target, double roll);

// The camera ray through continuous pixel position (px, py) (origin at the top-left image corner, pixel
// centres at +0.5), in world coordinates.
Ray camera_ray(const Camera& camera, double px, double py);

}  // namespace lumigauss::synth
