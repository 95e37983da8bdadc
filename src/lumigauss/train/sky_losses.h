#pragma once
// The losses that keep surfels out of the sky and tie the environment to the sky pixels
// (research/sky_and_floaters.md 3.3, 3.4, 4), and the per-pixel masks they act on. Maps are row-major, one
// value per pixel (three for colours), as RasterImages. Loss functions return the unweighted loss and ADD
// weight * dL/d(input) into their gradient outputs.
#include <span>
#include <vector>

#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/model/sky_residual.h"

namespace lumigauss {

// A photo pixel with any channel at or above this is taken as clipped (the sun, its glare): the sky losses
// leave it out, its true radiance is unknown.
inline constexpr double kSaturatedPhoto = 0.98;

// 1 where `mask` >= 0.5 and every pixel within `radius` (a square) does too, else 0. Pixels outside the
// image count as inside the mask, so that a sky touching the image border is not eaten there.
std::vector<float> eroded_mask(const Image& mask, int radius);

// Sum_p w_p alpha_p / sum_p w_p (0 when the weights are all 0): the mean accumulated opacity over the pixels
// that must stay empty (sky, or the outside of an object mask).
double alpha_penalty(std::span<const float> alpha, std::span<const float> weights, double weight,
                     std::span<float> g_alpha);

// The sky pixels' own loss on the sky colour S (3 per pixel, display space) and radiance R against the photo
// I, over pixels with sky_weight_p > 0 whose photo is not saturated (every channel < 0.98):
//   mean_p [ (1/3) sum_c |S_pc - I_pc| + 0.1 (1 - cos(S_p, I_p)) + 0.1 (1/3) sum_c |R_pc - I_pc^2.2| ]
// (NeuSky's sky-pixel loss, with L1 in place of the squared error: the sun's glare and clouds are outliers
// to a smooth sky. The linear term still pulls a radiance that went below the display floor, where S and
// its gradient are constant.) Adds weight * dL/dS into g_sky and weight * dL/dR into g_radiance.
double sky_colour_loss(std::span<const float> sky, std::span<const float> radiance,
                       std::span<const float> photo, std::span<const float> sky_weight, double weight,
                       std::span<float> g_sky, std::span<float> g_radiance);

// Pixels whose sky the photo already shows: the ray points above the horizon (up . d > 0), the photometric
// mask keeps the pixel, and the mean absolute RGB difference between photo and sky, averaged over the 3x3
// neighbourhood, is below `tolerance`. 1 there, else 0. For scenes without sky masks (Splatfacto-W).
std::vector<float> background_match_mask(std::span<const float> photo, std::span<const float> sky,
                                         std::span<const float> photometric_mask, std::span<const Vec3f> rays,
                                         Vec3f up, int width, int height, double tolerance);

// The gradient of the sky losses with respect to the per-photo sky residuals (model/sky_residual.h), stored
// as the residuals are: one row of SkyResiduals::kRowWidth per photo.
class SkyResidualGradients {
  public:
    // All zero, shaped as `residuals`.
    void reset(const SkyResiduals& residuals);
    // Adds g into the row of `image`.
    void add(int image, const Sh4Coeffs<float>& g);
    const std::vector<float>& values() const { return values_; }

  private:
    std::vector<float> values_;
};

}  // namespace lumigauss
