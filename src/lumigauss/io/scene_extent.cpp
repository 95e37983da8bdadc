#include "lumigauss/io/scene_extent.h"

#include <algorithm>

namespace lumigauss {

CameraExtent camera_extent(const std::vector<View>& views) {
    CameraExtent e;
    if (views.empty()) return e;
    for (const View& v : views) e.center += v.camera.center();
    e.center = e.center / double(views.size());
    double max_distance = 0;
    for (const View& v : views) max_distance = std::max(max_distance, length(v.camera.center() - e.center));
    e.radius = 1.1 * max_distance;
    return e;
}

PointBounds point_bounds(const std::vector<Vec3f>& points) {
    PointBounds b;
    for (const Vec3f& p : points) {
        for (int k = 0; k < 3; ++k) {
            b.min[k] = b.empty ? p[k] : std::min(b.min[k], p[k]);
            b.max[k] = b.empty ? p[k] : std::max(b.max[k], p[k]);
        }
        b.empty = false;
    }
    return b;
}

}  // namespace lumigauss
