#pragma once
// Turntable camera paths: cameras on a horizontal circle around the scene, all looking at its centre.
// Horizontal = perpendicular to the up axis (up_axis.h). The circle is placed where the scene's own cameras
// are on average: its centre is `centre` raised by their mean height above it (along up), its radius their
// mean horizontal distance from it, and it starts at the azimuth of the first of them, going
// counter-clockwise seen from above (right-handed about up).
#include <string>
#include <vector>

#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/io/camera.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

// Per-axis median of the points (robust to stray SfM points). Throws Error when there is no point.
Vec3d point_cloud_centre(const std::vector<Vec3f>& points);

// A camera with the intrinsics and size of `intrinsics`, at `eye`, looking at `target`, image up along
// `up` projected on the image plane (camera y = down). Falls back to another horizontal direction when the
// view is straight along `up`. Throws Error when eye == target.
Camera look_at(const Camera& intrinsics, Vec3d eye, Vec3d target, Vec3d up);

struct Orbit {
    Vec3d centre{};            // what every camera looks at
    Vec3d up{0, 0, 1};         // unit
    double height = 0;         // of the circle above the centre, along up
    double radius = 1;         // of the circle
    double start_azimuth = 0;  // radians, in the frame of orbit_basis
};

// Two unit vectors completing `up` to a right-handed frame (e1, e2, up): azimuth a is cos a e1 + sin a e2.
void orbit_basis(Vec3d up, Vec3d& e1, Vec3d& e2);

// The circle of the scene's cameras as described above. Throws Error when there is no camera or they all
// stand on the up axis through the centre.
Orbit orbit_from_cameras(const std::vector<Camera>& cameras, Vec3d centre, Vec3d up);

// `frames` cameras at azimuths start + 2 pi k / frames, named prefix + k with at least 3 digits
// ("orbit_000"). Throws Error when frames < 1.
std::vector<NamedCamera> orbit_cameras(const Orbit& orbit, const Camera& intrinsics, int frames,
                                       const std::string& prefix = "orbit_");

// prefix + k zero-padded to max(3, digits of count - 1).
std::string frame_name(const std::string& prefix, int k, int count);

}  // namespace lumigauss
