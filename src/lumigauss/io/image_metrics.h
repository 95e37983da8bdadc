#pragma once
// Image metrics of the official LumiGauss evaluation (research/lumigauss_official.md 6,
// `test_gt_env_map.py` with `utils/loss_utils.py` and scikit-image), plus the normal and albedo measures of
// the gt-env protocol (eval/gt_env.h).
//
// Images are `Image`s (io/image.h): row-major, `channels` interleaved values per pixel, values as given (the
// protocol clamps renders to [0, 1] before measuring). A mask is a one-channel Image of the same size whose
// value per pixel weighs that pixel (the protocol passes 0/1 masks); it applies to every channel.
//
// Formulas (C = channels, m_p = mask, sums over pixels p and channels c):
//   MSE  = sum m_p (x - y)^2 / (C sum m_p + 1e-6)                      (official, 1e-6 included)
//   MAE  = sum m_p |x - y|   / (C sum m_p + 1e-6)
//   PSNR = -10 log10(MSE + 1e-6)                                        (so identical images give 60 dB)
//   SSIM = sum m_p S_pc / (C sum m_p)                                   (NaN when the mask is empty)
// where S is the full SSIM map of skimage.metrics.structural_similarity(x, y, win_size=5, channel_axis=2,
// data_range=1, full=True) as the official evaluation calls it, i.e. skimage's defaults otherwise:
//   per channel, mu_x = U(x), mu_y = U(y), with U the 5x5 uniform (box) mean of scipy.ndimage.uniform_filter
//   (mode 'reflect': the image is extended by mirroring about its edge, d c b a | a b c d | d c b a),
//   v_x = N/(N-1) (U(x^2) - mu_x^2), v_y likewise, v_xy = N/(N-1) (U(xy) - mu_x mu_y), N = 25 (sample
//   covariance, use_sample_covariance=True), C1 = (0.01 R)^2, C2 = (0.03 R)^2, R = data_range = 1,
//   S = (2 mu_x mu_y + C1)(2 v_xy + C2) / ((mu_x^2 + mu_y^2 + C1)(v_x + v_y + C2)).
// The map is the full image size with the mirrored border, as skimage <= 0.25 returns it with full=True
// (its own mean crops (win-1)/2 pixels; the official code averages the full map under the mask instead).
// Everything is computed in double.
#include <array>
#include <cstddef>
#include <vector>

#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

inline constexpr double kPsnrMseEpsilon = 1e-6;                 // PSNR = -10 log10(MSE + 1e-6)
inline constexpr double kMaskedMeanEpsilon = 1e-6;              // MSE/MAE denominators
inline constexpr double kPsnrCap = 60.0;                        // -10 log10(1e-6): identical images
inline constexpr double kMaskFullCoverage = 1.0 - 0.5 / 255.0;  // "exactly 255" in an 8-bit mask

struct SsimOptions {
    int win_size = 5;  // odd; the official evaluation passes 5 (skimage's default is 7)
    double data_range = 1.0;
    double k1 = 0.01, k2 = 0.03;
    bool sample_covariance = true;  // N/(N-1) normalisation, skimage's use_sample_covariance=True
};

double masked_mse(const Image& x, const Image& y, const Image& mask);
double masked_mae(const Image& x, const Image& y, const Image& mask);
double psnr_from_mse(double mse);

// The SSIM map (same size and channels as the inputs). Throws Error if the shapes differ, the window is
// even or larger than the image.
Image ssim_map(const Image& x, const Image& y, const SsimOptions& options = {});
// sum m_p S_pc / (C sum m_p); NaN for an empty mask.
double masked_ssim(const Image& x, const Image& y, const Image& mask, const SsimOptions& options = {});

struct ImageMetrics {
    double psnr = 0, ssim = 0, mse = 0, mae = 0;
};
// All four of the official metrics for one image pair.
ImageMetrics image_metrics(const Image& x, const Image& y, const Image& mask,
                           const SsimOptions& options = {});

// Each value clamped to [0, 1] (NaN -> 0), as the official evaluation clamps its renders.
Image clamp01(const Image& image);

// Grey-level erosion (minimum) with a size x size square, pixels outside the image ignored (OpenCV's
// cv2.erode default border); `iterations` times. One channel.
Image erode_mask(const Image& mask, int size = 5, int iterations = 1);
// 1 where the value >= threshold, else 0. One channel.
Image binarize_mask(const Image& mask, float threshold = float(kMaskFullCoverage));
// The official evaluation mask from a grey mask at the image size: erode once with 5x5, then keep only
// full-coverage pixels (official: integer division of the 8-bit value by 255).
Image official_eval_mask(const Image& grey);
// Number of pixels with a mask value > 0.5.
std::size_t mask_pixels(const Image& mask);

// Angle between two directions in degrees (atan2(|a x b|, a.b), exact near 0 and 180); a zero vector gives
// NaN.
double angle_deg(Vec3d a, Vec3d b);

struct AngularErrorStats {
    double mean_deg = 0, median_deg = 0;
    std::size_t pixels = 0;   // pixels measured (mask on, ground truth defined)
    std::size_t missing = 0;  // of those, pixels where the prediction had no normal (counted as 90 deg)
};
// Per-pixel angles between normal maps (3 channels, any length; normalised here) over the pixels where the
// mask is > 0.5 and the ground truth is longer than `min_length`. A prediction shorter than `min_length`
// (nothing rendered there) counts as 90 degrees, the expected angle of a random direction, and is counted
// in `missing`. The angles are appended to `angles` when it is given (pooled statistics).
AngularErrorStats normal_angular_error(const Image& predicted, const Image& truth, const Image& mask,
                                       double min_length = 1e-3, std::vector<double>* angles = nullptr);
// Mean and median (numpy's: the mean of the two middle values for an even count) of a list of angles.
AngularErrorStats angle_stats(std::vector<double> angles);

// Per-channel least-squares scale s_c minimising sum_p m_p (s_c x_pc - y_pc)^2 summed over a list of
// image pairs: s_c = sum m x y / sum m x^2 (1 where sum m x^2 is 0).
struct ScaleFitTerms {
    std::array<double, 4> xy{}, xx{};  // up to 4 channels
};
void add_scale_terms(const Image& x, const Image& y, const Image& mask, ScaleFitTerms& terms);
std::array<double, 4> scale_from_terms(const ScaleFitTerms& terms);
// x with channel c multiplied by scale[c].
Image scale_channels(const Image& x, const std::array<double, 4>& scale);

}  // namespace lumigauss
