#pragma once
// Writing a training run folder (its layout: model/run_files.h): the finished model of a training state and
// the log lines.
#include <string>

#include "lumigauss/model/run_files.h"
#include "lumigauss/train/trainer.h"

namespace lumigauss {

// model.ply, lighting.lgmlp, appearance.json and (when trained) sky.lgsky of the state.
void save_run_model(const RunPaths& paths, const TrainState& state);

// One log line (JSON object, no newline) for a step.
std::string step_log_line(const StepReport& report, double elapsed_seconds);

}  // namespace lumigauss
