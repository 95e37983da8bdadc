#pragma once
// The `.splat` web format (antimatter15/splat and the viewers that copied it): no header, 32 bytes per
// splat, little-endian:
//   bytes  0..11  float32 x, y, z
//   bytes 12..23  float32 scale x, y, z, linear: exp(log scale_0), exp(log scale_1), kThinScale (1e-6)
//   bytes 24..27  uint8 r, g, b, a: round(255 * baked colour), round(255 * sigmoid(opacity))
//   bytes 28..31  uint8 quaternion w, x, y, z of the normalised quaternion, each clamp(round(q * 128 + 128),
//                 0, 255)
// Splats are written in decreasing exp(scale_0 + scale_1) * sigmoid(opacity) (larger and more opaque first,
// as the reference converter sorts them, so that a progressive loader shows the important ones first);
// ties keep the model's order.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

inline constexpr int kSplatBytes = 32;

struct SplatRecord {
    Vec3f position{};
    Vec3f scale{};               // linear
    Vec3f colour{};              // [0, 1] (clamped when encoded)
    float alpha = 0;             // [0, 1]
    Vec4f rotation{1, 0, 0, 0};  // w first; normalised when encoded
};

// The 32 bytes of one splat (layout above).
std::array<std::uint8_t, kSplatBytes> encode_splat(const SplatRecord& s);

// The records of a model with baked colours (3 per surfel), in the model's order.
std::vector<SplatRecord> splat_records(const SurfelModel& model, const std::vector<float>& colours);

// Sorts (see above) and writes the records atomically. Throws Error naming the file on I/O failure.
void write_splat_file(const std::string& path, std::vector<SplatRecord> records);

}  // namespace lumigauss
