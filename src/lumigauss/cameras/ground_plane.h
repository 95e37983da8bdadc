#pragma once
// The ground under the cameras, found in a point cloud (SfM points or surfel centres): the plane through the
// most points below the cameras whose normal is within kMaxGroundTilt of a guessed up. It pins what the
// cameras' level x axes leave open (up_axis.h): when every photo faces one way, the cameras alone fix the up
// only about their common x axis.
#include <cstddef>
#include <vector>

#include "lumigauss/math/vec.h"

namespace lumigauss {

inline constexpr double kMaxGroundTilt = 25.0;  // degrees between the guessed up and a ground candidate

struct GroundPlane {
    bool found = false;
    Vec3d normal{};                           // unit, on the guessed up's side
    double offset = 0;                        // dot(normal, p) of the plane's points
    std::size_t inliers = 0, candidates = 0;  // points on the plane; points below the cameras
};

// The ground in `points` below `camera_centres` along `up_guess`. A plane is found among the points below
// the cameras' median height by a seeded RANSAC (deterministic: the same input gives the same plane), when at
// least a fifth of them (and 20) lie on it within 1 % of the cameras' spread (or of the points' when the
// cameras are at one place), then refined by a least-squares fit to every point on it. Not found without
// such a plane: no points below, a sloped or broken ground, too few points.
GroundPlane find_ground_plane(const std::vector<Vec3d>& points, const std::vector<Vec3d>& camera_centres,
                              Vec3d up_guess);

}  // namespace lumigauss
