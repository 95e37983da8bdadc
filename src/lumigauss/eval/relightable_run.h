#pragma once
// What the evaluation protocols read of a trained run: the relightable surfels and each training photo's
// learned light as plain SH coefficients (not the lighting network that produced them), so that a test can
// stand an oracle in for a run: the true surfels lit by the true light (relightable_from_surfels).
#include <string>
#include <vector>

#include "lumigauss/model/splat_ply.h"
#include "lumigauss/model/surfel_model.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_side.h"

namespace lumigauss {

struct RelightableRun {
    std::string dir;
    SurfelModel model;
    std::vector<std::string> image_names;      // appearance.json, in embedding order
    std::vector<ShCoeffs<double>> learned_sh;  // the lighting MLP's env_sh(i) of each of them
    int downscale = 0;                         // config.json "downscale"; 0 if unknown
    bool sky_background = false;               // trained with the photo's sky behind the surfels
    SkyHorizon sky_horizon;                    // where that sky ends below the horizon (TrainedRun's)
    SurfelSideRule side_rule;                  // which side of a surfel a camera sees (TrainedRun's)
};

// A run folder (model.ply, lighting.lgmlp, appearance.json and config.json if present) or a bare relightable
// PLY (model/trained_run.h's load_run_or_ply: no photos, so no learned lights). Throws Error naming the
// first missing or malformed file.
RelightableRun load_relightable_run(const std::string& path);

// A relightable model with the geometry and colour of a 2DGS surfel model (e.g. gt/surfels.ply, whose colour
// is the linear albedo rho): model albedo = (rho / pi)^(1/2.2), so that with learned SH = exposure * true SH
// (light scale 1) its unshadowed colour is (exposure rho/pi E)^(1/2.2), the photo up to the sRGB curve; both
// transfer sets are the cosine lobes of their side's normal (unoccluded: shadowed == unshadowed).
SurfelModel relightable_from_surfels(const ViewDependentSurfels& surfels);

}  // namespace lumigauss
