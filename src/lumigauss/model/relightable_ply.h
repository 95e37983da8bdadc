#pragma once
// The official LumiGauss PLY (`save_ply` / `load_ply`, research/lumigauss_official.md 7), raw float32 values:
//   x y z, nx ny nz (zeros), f_dc_positive_0..2, f_rest_positive_0..23, f_dc_negative_0..2,
//   f_rest_negative_0..23, albedo_0..2, opacity (logit), scale_0..1 (logs), rot_0..3 (w first).
// f_dc/f_rest are channel-major (transpose(1, 2).flatten): f_rest_*_{c * 8 + k - 1} is channel c of SH
// coefficient k (1..8); SurfelModel stores [k * 3 + c].
#include <string>

#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

void save_relightable_ply(const std::string& path, const SurfelModel& model);
// The raw parameters of a saved model. Throws Error naming the file for a missing property.
SurfelModel load_relightable_ply(const std::string& path);

}  // namespace lumigauss
