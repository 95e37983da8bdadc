#pragma once
// A finished training run, loaded for rendering and evaluation: the surfels (model.ply), the lighting MLP
// (lighting.lgmlp) and the photo names in embedding order (appearance.json), plus the training resolution
// from config.json when present. The run folder layout is run_folder.h's.
#include <string>
#include <vector>

#include "lumigauss/scene/gaussian_model.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/train/lighting_mlp.h"
#include "lumigauss/train/run_folder.h"

namespace lumigauss {

struct TrainedRun {
    std::string dir;
    RunPaths paths;
    GaussianModel model;
    LightingMlp lighting;
    std::vector<std::string> image_names;  // appearance.json, in embedding order
    int downscale = 0;                     // config.json "downscale"; 0 if unknown

    // Embedding index of the training photo called exactly `name`, or -1.
    int find_image(const std::string& name) const;
    // The learned environment radiance SH of training photo `index` (lighting.env_sh(index)).
    ShCoeffs<double> learned_sh(int index) const;
};

// Loads model.ply, lighting.lgmlp, appearance.json (and config.json if present) of a run folder. Throws Error
// naming the folder or the first missing or malformed file, or the mismatch between the number of
// embeddings and of photos.
TrainedRun load_trained_run(const std::string& dir);

}  // namespace lumigauss
