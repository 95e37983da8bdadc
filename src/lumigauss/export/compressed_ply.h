#pragma once
// PlayCanvas's compressed PLY (SuperSplat, splat-transform and the PlayCanvas engine open it; the layout
// with colour ranges and an `sh` element, 2024 on): a binary little-endian PLY of three elements,
//   chunk  ceil(N / 256) rows of 18 float32: min_x min_y min_z max_x max_y max_z, min_scale_x..z,
//          max_scale_x..z, min_r min_g min_b, max_r max_g max_b
//   vertex N rows of 4 uint32: packed_position, packed_rotation, packed_scale, packed_color
//   sh     N rows of 3 K uchar f_rest_* (K = 3, 8 or 15 for SH degree 1, 2, 3; absent for degree 0)
// Splat i belongs to chunk i / 256, whose bounds quantise it:
//   position, log scale   11/10/11 bits (x in bits 31-21, y 20-11, z 10-0) of (v - min) / (max - min); the
//                         scale bounds clamped to [-20, 20]
//   colour                R G B A bytes from the high end: (0.5 + Y00 f_dc) between the chunk's colour
//                         bounds, and sigmoid(opacity) (never normalised)
//   rotation              smallest three: bits 31-30 the index of the largest |component| (w x y z order),
//                         made positive; the other three in index order, 10 bits each of c / sqrt 2 + 1/2
//   sh                    byte = clamp(floor((c / 8 + 1/2) 256), 0, 255), channel-major as the 3DGS PLY
// Every field is rounded as floor(v (2^bits - 1) + 1/2), clamped. The splats are written in Morton order of
// their positions, so that each chunk's bounds are tight.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lumigauss/export/gaussian_splats.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

inline constexpr std::size_t kCompressedChunkSize = 256;

// The order that sorts `positions` by their 30-bit Morton code in the points' bounding box (stable; the
// input order where the bounds are degenerate or not finite).
std::vector<std::size_t> morton_order(std::span<const Vec3f> positions);

// The whole file for `splats` in the order given. Throws Error when a value is not finite, a splat's
// `rest` does not hold 3 x ((sh_degree + 1)^2 - 1) values, or the degree is not 0..3.
std::string compressed_ply_bytes(std::span<const GaussianSplat> splats, int sh_degree);

// The surfels as 3DGS splats (export/gaussian_splats.h), with `view_sh` as in
// write_3dgs_ply, in Morton order, written atomically to `path`.
void write_compressed_ply(const std::string& path, const SurfelModel& model,
                          const std::vector<float>& view_sh, int sh_degree);

}  // namespace lumigauss
