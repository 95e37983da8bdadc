#pragma once
// Niantic's SPZ (github.com/nianticlabs/spz, format version 3): gzip around a 16-byte header and the
// splats' attributes, one array after the other, all little-endian:
//   header     u32 magic 0x5053474e ("NGSP"), u32 version 3, u32 count, u8 SH degree, u8 fractional bits
//              (12), u8 flags (0), u8 0
//   positions  count x 3 x 24-bit signed fixed point (value * 2^12, rounded)
//   alphas     count x u8: round(255 sigmoid(opacity))
//   colours    count x 3 x u8: round(255 (0.15 f_dc + 0.5)), f_dc the DC coefficient of the 3DGS PLY
//   scales     count x 3 x u8: round(16 (log scale + 10)); the surfel's thin third axis lands at 0
//   rotations  count x u32: the unit quaternion as "smallest three": bits 30-31 the index (x, y, z, w order)
//              of the largest component, made positive; then per other component, in index order, a sign
//              bit and 9 bits of round(511 |q| / sqrt(1/2)), the first one in the highest 10 bits
//   sh         count x ((degree + 1)^2 - 1) x 3 x u8, the colour channel fastest: round(128 c + 128),
//              rounded to multiples of 8 (band 1) or 16 (bands 2, 3) and clamped to [0, 255]
// SPZ's frame is right-handed with +y up (OpenGL's right, up, back): the model is turned by the smallest
// rotation that takes the world's `up` to +y before it is written, and its view-dependent colours (the
// two-sided SH of export/two_sided_sh.h) are computed in that frame. Coefficients outside SPZ's [-1, 1)
// clamp: a surfel whose two sides differ by more than about 0.7 loses some of the difference.
#include <span>
#include <string>
#include <vector>

#include "lumigauss/export/baked_colours.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

inline constexpr std::uint32_t kSpzMagic = 0x5053474e;
inline constexpr int kSpzFractionalBits = 12;

// The smallest rotation taking `up` to +y (world_turn.h rotation_taking; half a turn about z for -y).
Mat3d rotation_to_y_up(Vec3d up);

// The uncompressed SPZ stream (header and arrays) of `model` with baked `sides`, turned so that `up` is +y.
// `cameras` (camera centres in the world frame) choose the side of one-colour splats (degree 0). Throws
// Error when a position does not fit 24-bit fixed point (|x| >= 2048 after the turn) or the degree is not
// 0..3.
std::string spz_stream(const SurfelModel& model, const SurfelSides& sides, int sh_degree, Vec3d up,
                       std::span<const Vec3d> cameras);

// gzip(spz_stream(...)) written atomically to `path`.
void write_spz_file(const std::string& path, const SurfelModel& model, const SurfelSides& sides,
                    int sh_degree, Vec3d up, std::span<const Vec3d> cameras);

}  // namespace lumigauss
