#pragma once
// The ground-truth environment of the official SOL-NeRF evaluation (research/lumigauss_official.md 6,
// `process_environment_map_image` with Chalmers' `getCoefficientsFromImage`): an LDR panorama photo turned
// into degree-2 radiance SH exactly as there, so that the rotation ranges hand-tuned for it still apply.
//
//   1. Read the JPG as value/255. No sRGB linearisation.
//   2. Fake HDR: every channel value > threshold is multiplied by scale (per value, not per pixel).
//   3. If wider than 1000 pixels, resize to 1000 x 500, bicubic (OpenCV, eval/opencv_resize.h).
//   4. coeff_k = sum over pixels of value * Y_k(d) * dOmega, with, for a W-wide panorama and H = floor(W/2)
//      rows (the official code takes the height from the width, so the panorama must be 2:1):
//        theta = pi row / H, phi = 2 pi col / W            (pixel corners: no half-pixel offset)
//        dOmega(row) = (2 pi / W) (cos(ts - pi/2H) - cos(ts + pi/2H)),  ts = pi (1 - (row + 0.5) / H)
//      and Y^CS, the real SH with the Condon-Shortley phase in that spherical frame.
//   5. Frame: Y^CS(theta, phi) equals our basis (shading/sh.h, no CS phase) at the direction
//        d = (-sin theta cos phi, -sin theta sin phi, cos theta),
//      so the coefficients are our SH of the panorama placed that way: top row = +z, the centre column
//      (phi = pi) = +x, a quarter width from the left (phi = pi/2) = -y. The azimuth of d is phi + pi and
//      grows to the right, while a real z-up scene seen from inside has it decreasing to the right (our own
//      convention, shading/envmap.h), so this projection sees the panorama MIRRORED left-right compared
//      with `lumigauss env`. It is reproduced as is: the official rotation ranges were tuned with it.
// The protocol then rotates these coefficients (eval/official_sh_rotation.h).
#include <cstddef>
#include <string>

#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

inline constexpr int kOfficialPanoramaMaxWidth = 1000;  // wider panoramas are resized to 1000 x 500

// Direction (in the frame of shading/sh.h) of the pixel corner (row, col) of a `width`-wide panorama.
Vec3d official_panorama_direction(int row, int col, int width);
// dOmega of the pixels of `row` (sums to 4 pi over the floor(width/2) rows).
double official_pixel_solid_angle(int row, int width);

// Steps 3 to 5 on a panorama already read and boosted. 1-channel panoramas are taken as gray, alpha is
// ignored. Throws Error when the image is empty, not 2:1 after the resize (H != floor(W/2)), or holds a
// non-finite value.
ShCoeffs<double> official_project_panorama(const Image& panorama);

struct OfficialEnvironment {
    ShCoeffs<double> sh;        // in the frame of step 5, before any rotation
    std::size_t boosted = 0;    // values the fake HDR multiplied
    int width = 0, height = 0;  // of the file
};

// Steps 1 to 5 on a file. The boost applies to LDR files (PNG, JPEG); HDR and EXR panoramas are radiance
// already and used as stored. Throws Error naming the file when it is missing, unreadable, not 2:1 or holds a
// non-finite value, or when scale is not positive.
OfficialEnvironment official_environment_sh(const std::string& path, double threshold, double scale);

}  // namespace lumigauss
