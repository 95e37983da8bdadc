#pragma once
// Surface normals of a point cloud from its local neighbourhoods, so that surfels start lying in the surface
// their SfM points were triangulated on instead of in random orientations. A randomly turned surfel of a
// sparse ground point next to a camera stands up like a wall metres wide in front of it (issue #25); one
// lying in the ground plane is seen edge-on from there.
#include <vector>

#include "lumigauss/math/symmetric_eigen.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

// Per point: the unit eigenvector of the smallest eigenvalue of the covariance of the point and its k nearest
// neighbours (principal component analysis; sign arbitrary). +z where fewer than 3 points exist.
std::vector<Vec3f> point_normals(const std::vector<Vec3f>& points, int k = 16);

// A unit quaternion (w, x, y, z) whose rotation's third column is the unit vector n.
Vec4<double> quaternion_with_normal(Vec3d n);

}  // namespace lumigauss
