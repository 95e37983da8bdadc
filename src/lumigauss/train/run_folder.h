#pragma once
// Writing a training run folder (its layout: model/run_files.h): the finished model of a training state and
// the log lines.
#include <cstddef>
#include <optional>
#include <string>

#include "lumigauss/model/run_files.h"
#include "lumigauss/train/trainer.h"

namespace lumigauss {

// model.ply, lighting.lgmlp, appearance.json (with the photos' exposures, Trainer::exposures) and (when
// trained) sky.lgsky of the state.
void save_run_model(const RunPaths& paths, const TrainState& state, const std::vector<float>& exposures);

// The scores of a run's held-out photos for one snapshot of its model: means over the photos scored.
struct HeldOutScore {
    std::size_t photos = 0;
    double psnr = 0;  // of the shadowed render
};

// What scoring a snapshot adds to its iteration's log line: the score ("held_out_psnr", "held_out_photos")
// and its time ("held_out_s"), or the error of a scorer that failed ("held_out_error").
struct HeldOutLog {
    std::optional<HeldOutScore> score;
    double seconds = 0;
    std::string error;
};

// One log line (JSON object, no newline) for a step.
std::string step_log_line(const StepReport& report, double elapsed_seconds, const HeldOutLog& held_out = {});

}  // namespace lumigauss
