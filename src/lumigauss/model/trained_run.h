#pragma once
// A finished training run, loaded for rendering and evaluation: the surfels (model.ply), the lighting MLP
// (lighting.lgmlp) and the photo names in embedding order (appearance.json), plus the training resolution
// from config.json when present. The run folder layout is run_files.h's.
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/model/run_files.h"
#include "lumigauss/model/sky_residual.h"
#include "lumigauss/model/surfel_model.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_side.h"

namespace lumigauss {

struct TrainedRun {
    std::string dir;
    RunPaths paths;
    SurfelModel model;
    LightingMlp lighting;
    std::vector<std::string> image_names;  // appearance.json, in embedding order
    std::vector<double> exposures;         // appearance.json's per photo (1 each unless exif_exposure)
    int downscale = 0;                     // config.json "downscale"; 0 if unknown
    bool sky_background = false;           // config.json "sky_background": trained with the sky drawn behind
    SkyResiduals sky_residuals;            // sky.lgsky when present (per-photo sky residuals)
    // config.json "sky_pins_light": whether the sky's pixels shaped the photos' lights in training (true
    // without the record, as every run before the key). False: the sky was the residual's alone.
    bool sky_pins_light = true;
    double lambda_sky_residual = 0;    // config.json's L2 weight on those residuals (0 without the record)
    double lambda_sky_hemisphere = 0;  // config.json's hemisphere prior on them (0 without the record)
    // The world's up as the training photos that scene.json records give it (camera_up_direction); none
    // without the record (a bare PLY, a run of an older version).
    std::optional<Vec3d> photos_up;
    // The world-to-camera rotations and centres of the cameras of those training photos (empty without the
    // record). The centres say which side of each surfel the photos saw, for exports that hold one colour
    // per surfel.
    std::vector<Mat3d> photo_rotations;
    std::vector<Vec3d> photo_centres;
    // Where that sky ends below the horizon: config.json sky_horizon_start/fade, about photos_up (no horizon
    // without it, as the run was trained then), and with config.json ground_backdrop the ground drawn there
    // (its albedo from the surfels, model/ground_albedo.h, as training computed it at its last iteration).
    SkyHorizon sky_horizon;
    // Which side of each surfel a camera sees, as the run was trained: config.json grazing_side_degrees
    // about photos_up (shading/surfel_side.h); the official rule without either.
    SurfelSideRule side_rule;

    // Embedding index of the training photo called exactly `name`, or -1.
    int find_image(const std::string& name) const;
    // The learned environment radiance SH of training photo `index`: exposures[index] x
    // lighting.env_sh(index).
    ShCoeffs<double> learned_sh(int index) const;
    // The up for --up auto: photos_up refined by the ground under those cameras in the surfels
    // (scene_up_direction, cameras/up_axis.h); none without photos_up. photos_up stays the trained sky's.
    // Computed on each call (a RANSAC over up to 20000 surfel centres, 10-30 ms), so that loading a run
    // costs nothing for the commands that never ask.
    std::optional<Vec3d> scene_up() const;
};

// Loads model.ply, lighting.lgmlp, appearance.json (and config.json and scene.json if present) of a run
// folder. Throws Error naming the folder or the first missing or malformed file, or the mismatch between the
// number of embeddings and of photos.
TrainedRun load_trained_run(const std::string& dir);

// True when `path` names a regular file ending in .ply (case-insensitive).
bool is_bare_ply(const std::string& path);

// The files load_run_or_ply(path) reads: a run folder's (run_paths), or for a bare PLY its folder's with
// `model` the PLY itself.
RunPaths run_paths_of(const std::string& path);

// A run folder through load_trained_run, or a bare relightable PLY in the official LumiGauss layout
// (model/relightable_ply.h: what the Python code's `save_ply` writes, and a run's model.ply) as a run with no
// photos (dir = the PLY's folder, paths.model = the PLY), so that models trained with the official code can
// be relit and exported with external lights (SH files, panoramas). Throws Error naming the path when it is
// neither, or what load_trained_run / load_relightable_ply throw.
TrainedRun load_run_or_ply(const std::string& path);

}  // namespace lumigauss
