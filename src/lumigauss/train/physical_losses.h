#pragma once
// The physical losses of LumiGauss over a whole model (research/lumigauss_official.md 4.2, 4.3):
//   transfer losses l_[0,1], l_consistency, l_shadow over ALL surfels, with the transfer set and the
//   (detached) normal selected by the current camera, and `samples` fresh cube-normalised directions per
//   surfel per iteration;
//   l_+ on the photo's clean environment SH: mean of v^2 over the negative radiance values v at
//   `samples` shared cube-normalised directions.
// Directions come from a counter-based generator keyed by (seed, iteration, surfel), so a run is
// reproducible, independent of the number of threads, and resumable from the iteration number alone.
#include <cstdint>

#include "lumigauss/model/view_shading.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/train/gaussian_model.h"

namespace lumigauss {

struct TransferLossResult {
    TransferLosses<double> losses;  // unweighted values
    double weighted = 0;            // sum of weight * loss
};

// Computes the three transfer losses; when any weight is non-zero and `backward` is set, adds the gradient
// of the weighted sum into channel 0 of the transfer sets in use (model.grad(TransferPositive/Negative)).
TransferLossResult model_transfer_losses(GaussianModel& model, const ViewNormals& normals, int samples,
                                         std::uint64_t seed, std::int64_t iteration,
                                         const TransferLossWeights<double>& weights, bool backward);

// l_+ (unweighted value). Adds weight * dL/denv into g_env.
double env_nonnegativity_loss(const ShCoeffs<float>& env, int samples, std::uint64_t seed,
                              std::int64_t iteration, double weight, ShCoeffs<float>& g_env);

}  // namespace lumigauss
