#pragma once
// `lumigauss synth`: procedural landmark scenes rendered by a small CPU ray tracer into a dataset in the
// form real users bring (COLMAP text model, sRGB photos, static-scene masks, split.csv) plus ground truth in
// the layout and conventions of data/plaza (meta.json, env/COND_sh.txt, gt/{albedo,normal,mask,transient}),
// so that one evaluation path serves both, and the static scene as ground-truth surfels (gt/surfels.ply, the
// 2DGS PLY layout). The generated README.md states every convention.
//
// Deterministic: the same options give byte-identical files, whatever the number of threads.
#include <cstdint>
#include <string>

namespace lumigauss::synth {

struct SynthOptions {
    std::string output_dir;
    std::string scene = "plaza";  // plaza | temple (landmark_names())
    int width = 160, height = 120;
    int n_train = 40, n_test = 6;
    std::uint64_t seed = 1;
    double transient_fraction = 1.0 / 3.0;  // share of training photos with pedestrians
    int samples_per_side = 2;               // 2 -> 2 x 2 stratified samples per pixel
    int point_candidates = 8000;            // surface samples tried for points3D
    double point_noise = 0.005;             // RMS point position noise, as a fraction of the scene diagonal
    int gt_surfels = 60000;                 // about this many ground-truth surfels (gt/surfels.ply); 0: none
    // masks/ as foreground masks of the landmark alone (255 on it; 0 on the ground, pedestrians and sky), as
    // photo collections of one object come; train them with mask_mode=object.
    bool object_masks = false;
    bool overwrite = false;  // replace an existing non-empty output folder's dataset files
    bool verbose = false;    // progress on stdout
};

// Presets: "tiny" (64x48, 8 train + 2 test: unit tests, ~1 s), "demo" (160x120, 40 + 6: tens of seconds on
// two cores), "bench" (320x240, 60 + 12, as data/plaza). Throws Error for an unknown name.
SynthOptions synth_preset(const std::string& name);

struct SynthSummary {
    int n_train = 0, n_test = 0, n_conditions = 0, n_points = 0, n_with_transients = 0, n_gt_surfels = 0;
    double seconds = 0;
};

// Renders and writes the dataset; throws Error (naming the folder or file) on invalid options or I/O failure.
SynthSummary generate_synthetic_scene(const SynthOptions& options);

}  // namespace lumigauss::synth
