#pragma once
// Per training photo, the residual of its sky's radiance (shading/sky_colour.h): 25 RGB coefficients of a
// degree-4 SH that only the sky drawn behind the surfels sees, stored flat as [image][k * 3 + c] so that an
// optimizer (train/adam.h, one row per photo) treats it as any parameter group. The parameters alone: their
// gradient lives with the trainer (train/sky_losses.h, SkyResidualGradients).
#include <string>
#include <vector>

#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss {

class SkyResiduals {
  public:
    static constexpr int kRowWidth = 3 * kSh4Count;

    SkyResiduals() = default;
    explicit SkyResiduals(int num_images);  // all zero

    int num_images() const { return int(params_.size() / kRowWidth); }
    bool empty() const { return params_.empty(); }
    Sh4Coeffs<float> get(int image) const;

    std::vector<float>& params() { return params_; }
    const std::vector<float>& params() const { return params_; }

  private:
    std::vector<float> params_;
};

// File (binary, little-endian), written atomically: magic "LGSKYR01", int32 number of photos, int32
// coefficients per channel (25), then the float32 values as stored above.
void save_sky_residuals(const std::string& path, const SkyResiduals& residuals);
// Throws Error naming the file if it is missing, truncated, has another magic or other dimensions.
SkyResiduals load_sky_residuals(const std::string& path);

}  // namespace lumigauss
