#pragma once
// The relightable model as the viewer's page downloads it (GET /model.bin): a compact little-endian binary
// holding the model's raw parameters bit for bit, so the page applies exactly the project's activations and
// shading (web/viewer/model.js decodes it; tests/fast/view_model_payload_test.cpp has a reference decoder).
//
//   offset  size      field
//   0       8         magic "LGVIEW01" (ASCII, no terminator)
//   8       4         u32 format version = 1
//   12      4         u32 N, the number of surfels
//   16      4         u32 floats per surfel = 31
//   20      12        zero (reserved)
//   32      N*31*4    seven float32 blocks, one after the other, each N rows in surfel order:
//                       xyz          N x 3  position
//                       rotation     N x 4  raw quaternion w x y z (normalised where used)
//                       scaling      N x 2  log s_u, log s_v            (activation exp)
//                       opacity      N x 1  logit                       (activation sigmoid)
//                       albedo       N x 3  raw a; albedo = max(0, Y00 a + 0.5)
//                       transfer_pos N x 9  channel 0 of the positive transfer set (the only channel the
//                       transfer_neg N x 9  shading reads, model/surfel_model.h), SH order of shading/sh.h
// Every block starts at a multiple of 4 bytes, so the page views each one as a Float32Array without copying.
// Total size: 32 + 124 N bytes.
#include <cstdint>
#include <string>

#include "lumigauss/model/surfel_model.h"

namespace lumigauss::view {

inline constexpr char kPayloadMagic[9] = "LGVIEW01";
inline constexpr std::uint32_t kPayloadVersion = 1;
inline constexpr std::size_t kPayloadHeaderBytes = 32;
inline constexpr int kPayloadFloatsPerSurfel = 3 + 4 + 2 + 1 + 3 + 2 * kTransferCoeffs;

// The payload of `model` (layout above). Throws Error when the model has more than 2^32 - 1 surfels.
std::string encode_model_payload(const SurfelModel& model);

}  // namespace lumigauss::view
