#pragma once
// COLMAP's polynomial lens models, and undistortion of a photo onto the pinhole camera with the same
// intrinsics (fx, fy, cx, cy) and size. A fisheye photo loses its periphery that way (the pinhole of the same
// focal length sees less than 90 degrees off axis).
//
// In normalized camera coordinates (u, v) = ((x - cx) / fx, (y - cy) / fy) of the ideal pinhole, a lens moves
// a point to (COLMAP, src/colmap/sensor/models.h; FULL_OPENCV is OpenCV's rational model):
//   r2 = u^2 + v^2,  R = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
//   u_d = u R + 2 p1 u v + p2 (r2 + 2 u^2),   v_d = v R + 2 p2 u v + p1 (r2 + 2 v^2)
// SIMPLE_RADIAL has k1; RADIAL k1, k2; OPENCV k1, k2, p1, p2; FULL_OPENCV all eight.
// The fisheye models are equidistant with a polynomial in the ray's angle theta = atan(r), r = |(u, v)|:
//   theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8),   (u_d, v_d) = (u, v) theta_d /
//   r
// SIMPLE_RADIAL_FISHEYE has k1; RADIAL_FISHEYE k1, k2; OPENCV_FISHEYE k1..k4. The thin-prism fisheyes are not
// handled.
//
// Undistortion keeps the camera's intrinsics: each pixel of the pinhole image takes the photo's colour where
// the lens put that ray (bilinear). Pixels whose ray the photo does not hold (outside it, or past the radius
// where the polynomial folds back) are invalid: the colour there is 0 and undistort_validity() is 0, so the
// dataset masks them out of every loss and score. COLMAP's image_undistorter instead picks new intrinsics to
// crop or pad; keeping them means the SfM poses and the rest of the pipeline need no change.
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

struct LensDistortion {
    double k1 = 0, k2 = 0, k3 = 0, k4 = 0, k5 = 0, k6 = 0;  // radial (k4..k6: denominator)
    double p1 = 0, p2 = 0;                                  // tangential
    bool fisheye = false;  // the equidistant model above, k1..k4 its polynomial in theta

    bool is_identity() const;
    // Where the lens puts the normalized pinhole point `p` (the equations above).
    Vec2<double> distort(Vec2<double> p) const;
};

// The distortion of a COLMAP camera model from its parameters (in cameras.txt order, as many as the model
// has). False for a model that is not SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV,
// SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE or OPENCV_FISHEYE.
bool colmap_lens_distortion(const std::string& model, const std::vector<double>& params, LensDistortion& out);

// For every pixel of the pinhole image of `camera` (its size): 1 where the photo holds the pixel's ray, else
// 0.
Image undistort_validity(const Camera& camera, const LensDistortion& lens);

// The photo `distorted` (camera.width x camera.height, any channel count) resampled onto the pinhole camera:
// bilinear; 0 in every channel where undistort_validity is 0.
Image undistort_image(const Image& distorted, const Camera& camera, const LensDistortion& lens);

}  // namespace lumigauss
