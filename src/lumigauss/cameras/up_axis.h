#pragma once
// The world's up for relighting: turning the environment (--rotate, --spin), placing a panorama (its top
// row is up) and orbiting the scene all happen about it. Written as a signed coordinate axis: "+z" (the
// synthetic scenes and Blender), "-y" (COLMAP/NeRF-OSR reconstructions whose cameras have y down), "+y",
// "x", ..., as any vector "X,Y,Z", or "auto": the up of the photos' cameras and of the ground under them
// (scene_up_direction), which is not rounded to an axis (a real reconstruction's up is rarely one).
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// "x", "+x", "-x", ... "-z" (case-insensitive), or three comma-separated numbers -> the unit vector. Throws
// Error on anything else (a zero or non-finite vector included).
Vec3d parse_up_axis(const std::string& text);

// The world's up direction from world-to-camera rotations (not rounded to an axis), for the horizon: photos
// are taken level, with their x axes (row 0 of R) horizontal even when they look up at a building, so up is
// the direction every x axis is perpendicular to (the smallest eigenvector of sum x x^T), signed along the
// cameras' mean -y. The mean -y itself tilts by the cameras' mean pitch (4 deg on the demo scene, whose
// photos mostly face one side). When the x axes do not pin it (all photos face one way), the mean -y
// without its part along them. Zero when there is no rotation or the mean -y vanishes.
Vec3d camera_up_direction(const std::vector<Mat3d>& world_to_camera);

// The cameras' up refined by the ground plane under them (ground_plane.h) in `points` (SfM points or surfel
// centres): the unit u minimising sum_i (u . x_i)^2 + w (1 - (u . n)^2), x_i the cameras' x axes, n the
// ground's normal, w = kGroundUpWeight x the number of cameras. The x axes (photos held level, each to a
// degree or two) pin the up about the directions they span; the ground decides it about the rest. Measured
// on plaza and the demo scene (bench/RESULTS.md): the training photos facing within 22.5 degrees of one way
// put the up 5.4 and 9.5 degrees off from the cameras alone, 1.2 and 1.1 with the ground; all the photos
// 0.2 and 0.6, unchanged; a street sloping 5 degrees leaks 0.4-1.1 degrees of its slope (2.1-2.8 for the
// photos facing one way). camera_up_direction's result when no ground is found (or no points are given).
inline constexpr double kGroundUpWeight = 0.05;
Vec3d scene_up_direction(const std::vector<Mat3d>& world_to_camera, const std::vector<Vec3d>& camera_centres,
                         const std::vector<Vec3d>& points);

// The up of the cameras and of the ground in `points` (scene_up_direction; the cameras alone without
// points). Throws Error when there is no camera or their rotations fix no up (the mean -y vanishes).
Vec3d estimate_up_axis(const std::vector<Camera>& cameras, const std::vector<Vec3d>& points = {});

// "+z", "-y", ... for a coordinate axis, else "X,Y,Z" (6 decimals), which parse_up_axis reads back.
std::string up_axis_name(Vec3d up);

// The panorama frame (shading/envmap.h) whose top row looks along the unit vector `up`: a rotation with third
// column `up`. +z: identity; -y: rotation about +X by +90 deg (the y-down frame of envmap.h); +y: about +X by
// -90 deg; +x: about +Y by +90 deg; -x: about +Y by -90 deg; -z: about +X by 180 deg. Any other up: the frame
// of the nearest of these axes, tilted by the smallest rotation that takes that axis to `up` (so the
// panorama's centre column stays where the axis frame puts it, tilted with the world).
Mat3d panorama_frame_for_up(Vec3d up);

// The lighting turned by `degrees` about `up`, right-handed (seen from above, counter-clockwise: a sun at
// azimuth b moves to b + degrees), with the convention of sh_rotation.h. 0 returns the input unchanged.
ShCoeffs<double> rotate_about_up(const ShCoeffs<double>& sh, Vec3d up, double degrees);

// The angles of an N-frame spin starting at `start_degrees`: start + k * 360 / N, k = 0..N-1.
std::vector<double> spin_angles(int frames, double start_degrees);

}  // namespace lumigauss
