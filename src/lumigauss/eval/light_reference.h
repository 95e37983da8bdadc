#pragma once
// What a scene's photos can tell about their lights: a reference for the gt-env light-scale residual
// (light_scale.h). A photo shows its light only through the shading of the normals it sees. A degree-2 light
// has 9 directions per channel; a photo of level ground and a few upright walls sees 5 to 8 of them (every
// normal up or level: the xz and yz lobes change nothing in it, nor does one mix of the DC, z and 3z^2-1
// terms). The rest of a learned light comes from priors, and no fit to the photo can check it. So next to the
// residual of the whole light, gt-env reports:
// - the learned lights' residual on the part each photo sees (the seen residual), and
// - the residual of a reference that knows the scene's true albedo and normals (gt/albedo, gt/normal) and
//   fits each training photo's light to its shading, cast-shadow pixels dropped: about the best a degree-2
//   light learned from these photos can reach without knowing the unseen part.
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/eval/gt_scene.h"
#include "lumigauss/eval/relightable_run.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/math/symmetric_eigen.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// One pixel of a photo for the reference: linear values, the radiance with the photo's exposure in it.
struct ShadingSample {
    Vec3d albedo, normal, radiance;
};

struct PhotoLightReference {
    ShCoeffs<double> light;         // Lambertian fit to the shading; zero on the unseen part
    SquareMatrix<kShCount> seen{};  // orthogonal projector onto the light directions the normals tell apart
    int seen_count = 0;             // its rank (0 to 9)
};

// The projector of the samples' normals (directions whose irradiance Gram eigenvalue is at least 1e-3 of the
// largest) and the least-squares light on it: radiance = albedo / pi * E(normal), refitted 4 times without
// the samples below 0.6 x the fit (cast shadows). Throws Error when there is no sample.
PhotoLightReference fit_photo_light_reference(const std::vector<ShadingSample>& samples);

// P applied to each channel of an SH light.
ShCoeffs<double> project_light(const SquareMatrix<kShCount>& projector, const ShCoeffs<double>& light);

struct LightReference {
    int photos = 0;                      // training photos with gt/albedo and gt/normal
    int min_seen = 0, median_seen = 0;   // seen directions per photo (of 9)
    double unseen_share = 0;             // sqrt(sum w |T - P T|^2 / sum w |T|^2), exposure-scaled true lights
    double reference_residual = 0;       // the reference lights' light-scale residual (whole lights)
    double reference_seen_residual = 0;  // ... on the seen part
    double learned_seen_residual = 0;    // the run's learned lights on the seen part
};

// Over the run's training photos (meta.json split "train", not in `exclude`) that have gt/albedo and
// gt/normal, pixels inside evaluation_mask, unclipped (every channel < 0.99), albedo >= 0.02 in each channel.
// Nothing when no such photo has a usable pixel (a scene without gt/albedo or gt/normal, a bare PLY).
std::optional<LightReference> light_reference(const RelightableRun& run, const Dataset& scene,
                                              const GtSceneMeta& meta,
                                              const std::vector<std::string>& exclude);

}  // namespace lumigauss
