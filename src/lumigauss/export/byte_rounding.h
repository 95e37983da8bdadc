#pragma once
// The byte of a value on the 0..255 scale, rounded to nearest and clamped: how the byte-packed export formats
// (splat, SPZ, glTF's COLOR_0) store colours, opacities and quantised coefficients.
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace lumigauss {

inline std::uint8_t rounded_byte(double v) {
    return std::uint8_t(std::clamp(std::round(v), 0.0, 255.0));
}

}  // namespace lumigauss
