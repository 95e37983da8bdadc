#pragma once
// Turning stored pixels upright as an EXIF Orientation tag (1 to 8) says the camera was held.
//   1 as stored          2 mirrored left-right     3 turned 180 degrees    4 mirrored top-bottom
//   5 transposed         6 turned 90 degrees clockwise   7 transversed    8 turned 90 degrees anticlockwise
// (5 and 7 are 6 and 8 mirrored left-right). 5 to 8 swap width and height.
#include "lumigauss/io/image.h"

namespace lumigauss {

inline bool orientation_swaps_axes(int orientation) {
    return orientation >= 5 && orientation <= 8;
}

// The image as it is meant to be seen: `stored` with `orientation` applied (a copy; 1 or an out-of-range
// value returns it unchanged).
Image upright_image(const Image& stored, int orientation);

}  // namespace lumigauss
