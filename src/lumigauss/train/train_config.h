#pragma once
// Every hyper-parameter of a training run in one struct, with the official LumiGauss values as the `paper`
// preset (research/lumigauss_official.md 4.5 and 5) and a `fast` preset for small scenes. A run saves its
// config as JSON next to the model; the same JSON (or any subset of its keys) can be loaded back with
// --config, and single keys overridden with --set key=value.
//
// Iterations are 1-based as in the official train.py (`for iteration in range(1, iterations + 1)`):
//   stage 1 (unshadowed warm-up)  iteration <  warmup
//   stage 2 (transfer fitting)    warmup <= iteration <= start_shadowed
//   stage 3 (shadowed)            iteration >  start_shadowed
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace lumigauss {

// The longest photo side -r auto trains at (downscale 0).
inline constexpr int kAutoMaxPhotoSide = 1600;

struct TrainConfig {
    std::string preset = "paper";
    std::uint64_t seed = 0;
    // -r: 1, 2, 4 or 8 (run_all.sh uses 1 on NeRF-OSR), or 0 = auto (the default presets): a new run takes
    // the smallest of them that brings the longest photo side to at most kAutoMaxPhotoSide (3DGS's loader
    // rescales photos wider than 1.6k px likewise when no -r is given) and records the factor it chose.
    int downscale = 1;

    // Schedule (5).
    std::int64_t iterations = 40000;
    std::int64_t warmup = 20000;
    std::int64_t start_shadowed = 20500;
    std::int64_t start_regularization = 6000;  // normal and distortion losses for iteration > this

    // Loss weights (4.5).
    double lambda_dssim = 0.2;
    double lambda_unshadowed_stage3 = 0.001;  // weight of the unshadowed image loss in stage 3
    double lambda_range01 = 0.001;            // l_[0,1]
    double lambda_env = 0.05;                 // l_+
    // The light below the horizon pulled towards the ground's reflection (train/ground_light_prior.h);
    // 0 = off, as officially. The ground's albedo it assumes: 0 = the model's own (in the gauge the sky
    // pins), > 0 = this physical albedo in the colour of the model's ground (free of the gauge).
    double lambda_ground_light = 0.0;
    double ground_light_albedo = 0.0;
    double lambda_consistency = 10.0;      // l_consistency (10 for NeRF-OSR scenes, run_all.sh)
    double consistency_final_ratio = 1.0;  // stage-3 l_consistency weight = lambda_consistency x this
    double lambda_shadow = 10.0;           // l_shadow (stage 3)
    double lambda_normal = 0.05;
    double lambda_distortion = 100.0;

    // Monte Carlo and noise (3.5, 4.2, 4.3).
    double env_noise_sigma = 0.025;
    int transfer_samples = 25;  // directions per surfel per iteration
    int env_samples = 10;       // directions for l_+

    // Learning rates (5). Position: log-linear from init to final (x scene extent) over position_max_steps.
    double lr_position_init = 1.6e-4;
    double lr_position_final = 1.6e-6;
    std::int64_t lr_position_max_steps = 30000;
    double lr_transfer = 0.002;
    double lr_opacity = 0.05;
    double lr_scaling = 0.005;
    double lr_rotation = 0.001;
    double lr_albedo = 0.0025;
    double lr_embedding = 0.002;
    double lr_mlp = 0.002;
    double lr_env_final_ratio = 10.0;  // stage 3: embedding and MLP rates divided by this

    // Densification (5).
    std::int64_t densify_from = 500;
    std::int64_t densify_until = 15000;
    std::int64_t densify_interval = 500;
    std::int64_t opacity_reset_interval = 3000;
    double densify_grad_threshold = 0.0002;
    double min_opacity = 0.05;
    // A reset sets every opacity to at most this. The official 0.01 is below min_opacity: a surfel that fewer
    // than about a third of the photos see cannot climb back over min_opacity before the next prune (Adam
    // moves the logit about lr_opacity per visit), so the reset itself deletes weakly observed surfaces.
    // Above min_opacity (3DGS's ratio: reset 0.01, prune 0.005) only surfels that the photos push down are
    // pruned.
    double opacity_reset_value = 0.01;
    double max_screen_size = 20.0;  // pixels; applied after the first opacity reset
    double percent_dense = 0.01;
    bool faithful_radii_reset = true;  // replicate the official zeroing of max_radii2D before the prune

    // Beyond the paper (issue #25): each switched off here (the paper preset), on in the default presets.
    // Surfels start in the plane of their SfM neighbourhood instead of randomly turned (point_normals.h).
    bool init_normals_from_points = false;
    // More starting points on the ground plane under the cameras, where the SfM points leave it bare
    // (train/ground_seeds.h).
    bool ground_seeds = false;
    // The photo's environment is drawn behind the surfels (colour += T_final * sky, shading/sky_colour.h).
    bool sky_background = false;
    // The sky ends below the horizon of the cameras' mean up direction: it starts to fade
    // sky_horizon_start degrees below it and is gone sky_horizon_fade degrees further down
    // (shading/sky_colour.h, sky_visibility); fade 0 = the environment is drawn in every direction. An
    // uncovered pixel well below the horizon is a hole in the ground: shown the environment's unconstrained
    // lower half, holes were painted by it and the learned lights grew a bright floor.
    double sky_horizon_start = 0.0;
    double sky_horizon_fade = 0.0;
    // Where the sky has faded below the horizon, the ground is drawn instead of black: the median albedo
    // of the surfels facing up (model/ground_albedo.h) lit by the photo's light. Holes in the near ground
    // of a new viewpoint then look like ground. Not with object masks (mask_mode "object"), whose outside is
    // empty space.
    bool ground_backdrop = false;
    // A level surfel seen within this many degrees of its own plane shows its upper side (the photos' up)
    // instead of the side facing the camera (shading/surfel_side.h): a few degrees of tilt in the fitted
    // ground no longer shows far cameras its underside, shaded by the light from below. 0 = off, as
    // officially. Saved with the run: every render of it (relight, eval, viewer) shades by the same rule.
    double grazing_side_degrees = 0.0;
    // Where sky masks exist: alpha pushed to 0 on sky pixels (mean alpha over the sky mask eroded by
    // sky_mask_erosion pixels), the environment supervised by the sky pixels it must reproduce (L1 plus
    // 0.1 x (1 - cosine) per pixel, saturated pixels skipped), and the normal/distortion losses kept off the
    // sky. The sky's own per-photo residual (degree 4, never used for shading; sky_colour.h), its L2 penalty
    // per iteration (sum of the squared coefficients of the photo drawn) and its learning rate.
    bool sky_residual = false;
    double lambda_sky_residual = 0.01;
    double lr_sky_residual = 0.02;
    // With sky residuals: each photo's sky radiance (light + residual), at those of 64 directions spread over
    // the upper hemisphere that its camera does not see, pulled towards the mean radiance of the photo's sky
    // pixels (its sky mask; without masks, the pixels the sky background already explains), squared error,
    // gradient to the residual only (train/sky_hemisphere_prior.h). Without it, a photo's light seen from a
    // new viewpoint drew a sky that no photo constrained, often black. 0 = off.
    double lambda_sky_hemisphere = 0.0;
    // Whether the sky pixels' gradient reaches the lighting. A degree-2 SH cannot draw a sky with a sun (it
    // saturates where the sun's lobe is, and rings below zero 90 degrees away), so a sky drawn from the light
    // alone bends each photo's light towards its sky's look. false: the sky's gradient goes to its residual
    // only (sky_residual), the light is shaped by the surfels' pixels alone.
    bool sky_pins_light = true;
    // The lighting network's output starts as this uniform radiance (0: as officially, its random bias only),
    // so that the sky and the shading see light from the first iteration (a sky below the radiance floor gets
    // no gradient).
    double lighting_init_radiance = 0.0;
    // The photos' EXIF exposure (io/photo_exif.h) as the lighting's starting point: photo i's environment is
    // 2^(mean EV - EV_i) x the network's output, a fixed factor the network then corrects as it needs
    // (photos without EXIF: 1). The factors are saved with the run (appearance.json) and every use of a
    // training photo's light includes them.
    bool exif_exposure = false;
    bool use_sky_masks = true;  // false: train as if the scene had none (to measure what they bring)
    double lambda_sky_alpha = 0.0;
    double lambda_sky_colour = 0.0;
    int sky_mask_erosion = 2;
    bool sky_free_regularizers = false;
    // Without sky masks: alpha pushed to 0 where the sky background already explains the photo (pixels whose
    // ray points above the horizon and whose 3x3 neighbourhood differs from the sky by less than the
    // tolerance, mean absolute difference over RGB), from iteration background_alpha_from on.
    double lambda_background_alpha = 0.0;
    double background_match_tolerance = 0.03;
    std::int64_t background_alpha_from = 500;
    // "transient": mask 0 = ignore the pixel (transients, as NeRF-OSR); "object": mask 0 = empty space (a
    // foreground mask of one object), where alpha is pushed to 0 like on the sky (weight lambda_sky_alpha).
    std::string mask_mode = "transient";
    // Floater hygiene: pruning (opacity < min_opacity, scale > 0.1 extent) goes on every densify_interval to
    // the end of training; the densification gradient of surfels nearer than densify_near_fraction x extent
    // is damped by (depth / (fraction x extent))^2 (Pixel-GS; 0 = off); an L1 penalty on opacity (3DGS-MCMC).
    bool prune_until_end = false;
    double densify_near_fraction = 0.0;
    double lambda_opacity = 0.0;
    // A pull on surfels whose tangent scales differ by more than max_scale_ratio (needles; see
    // train/scale_ratio_penalty.h); 0 = off, in every preset (measured: no cleaner new views).
    double lambda_scale_ratio = 0.0;
    double max_scale_ratio = 10.0;
    // After densification, once per opacity_reset_interval and at the end: surfels with more than this
    // share of their blend weight in the training photos on pixels that must stay empty (sky mask, an
    // object's outside, or the background-explained pixels) are removed (train/empty_space_prune.h); 0 = off.
    double empty_space_prune_share = 0.0;
    // At the last iteration's sweep: surfels whose blend weight summed over every training photo's
    // constrained pixels is below this many pixels are removed (they add less colour to the whole training
    // set than a few pixels: hidden inside or behind the surface, or out of every photo; LightGaussian's
    // global significance); 0 = off.
    double min_contribution_pixels = 0.0;
    // At the last iteration's sweep: surfels lower than the lowest training camera (along the photos' up)
    // that fewer than this many training photos see with at least a pixel of blend weight are removed
    // (train/empty_space_prune.h, remove_weakly_seen_ground); 0 = off. Seen by one or two photos, nothing
    // triangulates a surfel's depth and tilt: on the ground around the cameras such surfels are the streaks
    // of new views, and the ground backdrop draws the ground they leave. Off in every preset: it cleans
    // plaza's new views (the default schedule's spikes on test_0001 gone, +0.16 dB) but costs the training
    // photos the near ground they alone saw (their tile joints), and on the demo scenes the backdrop left
    // in their place is a darker band (-0.16 dB on the temple; bench/RESULTS.md, session 32).
    int min_ground_views = 0;
    // In the shadowed stage, every surfel's transfer is the SH projection of the light its own model lets
    // reach it (model/visibility_transfer.h: the other surfels traced as shadow casters), baked at the
    // stage's first iteration, every geometric_transfer_every iterations and at the last one, and frozen
    // in between (no transfer losses, no transfer learning rate): the shadows come from the geometry instead
    // of being learned per surfel from the training lights alone; 0 = off (the learned transfer).
    std::int64_t geometric_transfer_every = 0;
    // The share of the blocked light the baked transfer lets through, as the blocker's reflection
    // (VisibilityTransferOptions::bounce): the photos hold interreflections, which nothing else carries.
    double shadow_bounce = 0.5;

    // Run bookkeeping (not in the official code).
    std::int64_t checkpoint_interval = 1000;  // iterations between checkpoints; 0 = only at the end/interrupt
    std::int64_t log_interval = 10;           // iterations between log lines; every loss term is logged
    // Every held_out_interval iterations of the shadowed stage and at the end, score the scene's held-out
    // photos into log.jsonl (`train` uses eval's holdout protocol: each photo's light fitted on its left
    // half, the right half scored); 0 = never.
    std::int64_t held_out_interval = 5000;
};

// The preset's values; throws Error for an unknown name (train_preset_names()).
TrainConfig train_preset(std::string_view name);
// "default", "fast", "paper", "paper-fast".
const std::vector<std::string>& train_preset_names();

// All fields as one flat JSON object, keys as the field names above (pretty-printed).
std::string train_config_to_json(const TrainConfig& config);

// Applies the keys of a JSON object onto `config` (keys not given keep their value). A key named "preset"
// first resets everything to that preset, then the other keys apply. Throws Error naming `source` (a
// file name or "--config") and the key for unknown keys, wrong types, or text that is not a JSON object.
void apply_train_config_json(TrainConfig& config, std::string_view json_text, std::string_view source);

// Applies "key=value" (value parsed as the field's type; bools accept true/false/1/0). Throws Error naming
// the key for unknown keys or unparsable values.
void apply_train_config_override(TrainConfig& config, std::string_view key_equals_value);

// A run of `iterations` on the config's schedule (as gsplat's steps_scaler): the stage boundaries, the
// regularisation start, the position LR decay, the densification window and the background-alpha start are
// multiplied by iterations / config.iterations, so that a short run still passes through all three stages
// (the transfer-fitting stage keeps at least one iteration). The densification and opacity-reset intervals
// stay (a rhythm of visits to the photos: scaled down, surfels could not recover from a reset before the next
// prune), and so do the checkpoint and log intervals. Throws Error if iterations < 1.
void scale_schedule(TrainConfig& config, std::int64_t iterations);

// One line per phase: the stages and the densification window, as `train` prints them at the start.
std::string schedule_summary(const TrainConfig& config);

// Checks consistency (iterations > 0, warmup <= start_shadowed, sample counts > 0, non-negative weights and
// rates, downscale in {0 (auto), 1, 2, 4, 8}, ...); throws Error naming the offending key.
void validate_train_config(const TrainConfig& config);

}  // namespace lumigauss
