#pragma once
// Shadow transfer from the model's own geometry (issue #25). A surfel's transfer set is the SH projection
// of the light it receives from each direction, t(w) = V(w) max(0, n.w) (research/lumigauss_official.md
// 3.3): the learned sets only know the lights of the training photos and the consistency loss, and relit
// under a new sun they neither darken the shadowed side of a wall nor keep the open ground bright. Here
// V(w) is the transmittance of the other surfels along the ray from the surfel (SurfelOcclusion), so
//   T_j = integral (1 - (1 - b)(1 - V(w))) max(0, n.w) Y_j(w) dw
//       = cosine_lobe_sh(n)_j - (1 - b) (pi / K) sum_k (1 - V(w_k)) Y_j(w_k)
// over K cosine-weighted, stratified directions of the surfel's hemisphere, where b (bounce) is the share
// of the blocked light that the blocker reflects on (the photos hold interreflections; the transfer has
// no other way to carry them). An unoccluded surfel gets the clamped-cosine lobe exactly, so the shadowed
// shading then equals the unshadowed one. Light from below the horizon is blocked like any other: the
// ground stands between a wall and the environment's lower half.
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

struct VisibilityTransferOptions {
    // The hemisphere's K = rows * rows directions, one per stratum. 8 (64 directions): against 576 the
    // shading of the fast plaza model's surfels differs by 1.3 % RMS (12 rows: 0.7 %), and trainings score
    // the same as with 12 rows in half the bake time (bench/RESULTS.md, session 34).
    int direction_rows = 8;
    // Crossings nearer than this (model units) do not count, so that neighbours of the same surface, tilted
    // a little, do not shade it.
    double start_distance = 0.0;
    // Surfels nearly parallel to the surfel and this close to its plane (model units) are other layers of
    // the same surface: a trained model stacks several on its ground.
    double layer_thickness = 0.0;
    // The share of the blocked light that still arrives, reflected by what blocks it (interreflection: the
    // occluders' albedo under the same light, roughly): 0 = black shadows, 1 = no shadows.
    double bounce = 0.0;
    unsigned seed = 1;  // jitters each surfel's directions inside their strata
};

struct VisibilityTransferReport {
    double mean_visibility = 1.0;    // cosine-weighted mean of V over both sides of every surfel
    double shadowed_fraction = 0.0;  // sides with a cosine-weighted visibility below one half
};

// Replaces both transfer sets of every surfel (all three stored channels) by the geometric transfer.
VisibilityTransferReport bake_visibility_transfer(SurfelModel& model,
                                                  const VisibilityTransferOptions& options = {});

}  // namespace lumigauss
