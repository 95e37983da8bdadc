#pragma once
// The two resamplings of the official SOL-NeRF evaluation (research/lumigauss_official.md 6), as OpenCV's
// cv2.resize computes them, so that environment maps and evaluation masks are prepared exactly as there:
//   * INTER_CUBIC: the environment panorama, 1000 x 500 when it is wider than 1000
//   (getCoefficientsFromImage);
//   * INTER_LINEAR (cv2.resize's default): the evaluation mask, to the photo's size.
// Both map output pixel d to the source position f = (d + 0.5) * src / dst - 0.5 (pixel centres aligned),
// separably along x and y, with source indices clamped to the image (OpenCV's replicated border) and no
// anti-aliasing when shrinking (OpenCV filters only with INTER_AREA).
//   cubic:  taps floor(f) - 1 .. floor(f) + 2, Keys' kernel with A = -0.75 (OpenCV's, not -0.5); it can
//           overshoot (negative values, values above the maximum) near edges, as OpenCV's does.
//   linear: taps floor(f), floor(f) + 1; a position left of the first pixel centre or right of the last one
//           takes that pixel alone.
// Values are computed in double and stored as float (OpenCV works in float for float images, and in 11-bit
// fixed point for 8-bit ones; the differences are below 1e-6 relative, or below half a code for 8 bits).
// Every channel is resampled alike.
#include "lumigauss/io/image.h"

namespace lumigauss {

Image resize_cubic_opencv(const Image& image, int new_width, int new_height);
Image resize_linear_opencv(const Image& image, int new_width, int new_height);

}  // namespace lumigauss
