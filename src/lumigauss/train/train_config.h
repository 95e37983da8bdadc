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

struct TrainConfig {
    std::string preset = "paper";
    std::uint64_t seed = 0;
    int downscale = 1;  // -r: 1, 2, 4 or 8 (run_all.sh uses 1 on NeRF-OSR)

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
    double lambda_consistency = 10.0;         // l_consistency (10 for NeRF-OSR scenes, run_all.sh)
    double consistency_final_ratio = 1.0;     // stage-3 l_consistency weight = lambda_consistency x this
    double lambda_shadow = 10.0;              // l_shadow (stage 3)
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
    double max_screen_size = 20.0;  // pixels; applied after the first opacity reset
    double percent_dense = 0.01;
    bool faithful_radii_reset = true;  // replicate the official zeroing of max_radii2D before the prune

    // Run bookkeeping (not in the official code).
    std::int64_t checkpoint_interval = 1000;  // iterations between checkpoints; 0 = only at the end/interrupt
    std::int64_t log_interval = 10;           // iterations between log lines; every loss term is logged
};

// The preset's values; throws Error for an unknown name ("paper" or "fast").
TrainConfig train_preset(std::string_view name);

// All fields as one flat JSON object, keys as the field names above (pretty-printed).
std::string train_config_to_json(const TrainConfig& config);

// Applies the keys of a JSON object onto `config` (keys not given keep their value). A key named "preset"
// first resets everything to that preset, then the other keys apply. Throws Error naming `source` (a
// file name or "--config") and the key for unknown keys, wrong types, or text that is not a JSON object.
void apply_train_config_json(TrainConfig& config, std::string_view json_text, std::string_view source);

// Applies "key=value" (value parsed as the field's type; bools accept true/false/1/0). Throws Error naming
// the key for unknown keys or unparsable values.
void apply_train_config_override(TrainConfig& config, std::string_view key_equals_value);

// Checks consistency (iterations > 0, warmup <= start_shadowed, sample counts > 0, non-negative weights and
// rates, downscale in {1, 2, 4, 8}, ...); throws Error naming the offending key.
void validate_train_config(const TrainConfig& config);

}  // namespace lumigauss
