#pragma once
// An undistorted pinhole camera in COLMAP's conventions:
//   X_cam = R X_world + t (world-to-camera), camera x right, y down, z forward;
//   pixel (i, j) -- column i, row j -- has its centre at (i + 0.5, j + 0.5) in the image plane
//   u = fx * x / z + cx, v = fy * y / z + cy.
#include <string>

#include "lumigauss/math/vec.h"

namespace lumigauss {

struct Camera {
    int width = 0;
    int height = 0;
    double fx = 0, fy = 0, cx = 0, cy = 0;
    Mat3d rotation = Mat3d::identity();  // world-to-camera
    Vec3d translation{};                 // world-to-camera

    Vec3d center() const { return -(transpose(rotation) * translation); }
    Vec3d world_to_camera(Vec3d p) const { return rotation * p + translation; }

    // Intrinsics for the same view at another image size. With pixel centres at +0.5, image-plane
    // coordinates scale about the image corner, so fx, cx (and fy, cy) scale by the same ratio.
    Camera resized(int new_width, int new_height) const {
        Camera c = *this;
        const double sx = double(new_width) / width, sy = double(new_height) / height;
        c.width = new_width, c.height = new_height;
        c.fx = fx * sx, c.cx = cx * sx, c.fy = fy * sy, c.cy = cy * sy;
        return c;
    }
};

}  // namespace lumigauss
