#pragma once
// How big a scene is: the 3DGS "cameras_extent" (used to scale densification thresholds and learning rates)
// and the bounding box of the SfM points.
#include <vector>

#include "lumigauss/io/dataset.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

struct CameraExtent {
    Vec3d center{};     // mean camera centre
    double radius = 0;  // 1.1 x the largest distance of a camera centre from `center` (3DGS getNerfppNorm)
};

struct PointBounds {
    bool empty = true;
    Vec3f min{}, max{};
};

CameraExtent camera_extent(const std::vector<View>& views);
PointBounds point_bounds(const std::vector<Vec3f>& points);

}  // namespace lumigauss
