#include "lumigauss/io/image_orientation.h"

#include <algorithm>

namespace lumigauss {

namespace {

// The stored pixel that lands at (x, y) of the upright image (w, h: the stored size).
struct StoredPixel {
    int x, y;
};

StoredPixel source_of(int orientation, int x, int y, int w, int h) {
    switch (orientation) {
        case 2:
            return {w - 1 - x, y};
        case 3:
            return {w - 1 - x, h - 1 - y};
        case 4:
            return {x, h - 1 - y};
        case 5:
            return {y, x};
        case 6:
            return {y, h - 1 - x};
        case 7:
            return {w - 1 - y, h - 1 - x};
        case 8:
            return {w - 1 - y, x};
        default:
            return {x, y};
    }
}

}  // namespace

Image upright_image(const Image& stored, int orientation) {
    if (orientation < 2 || orientation > 8) return stored;
    const bool swap = orientation_swaps_axes(orientation);
    Image out(swap ? stored.height : stored.width, swap ? stored.width : stored.height, stored.channels);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            const StoredPixel s = source_of(orientation, x, y, stored.width, stored.height);
            std::copy_n(&stored.pixels[stored.index(s.x, s.y, 0)], stored.channels,
                        &out.pixels[out.index(x, y, 0)]);
        }
    return out;
}

}  // namespace lumigauss
