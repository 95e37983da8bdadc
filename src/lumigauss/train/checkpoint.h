#pragma once
// Checkpoints of a training run: everything TrainState holds (config, iteration, surfels with their Adam
// moments and densification statistics, lighting model with its Adam moments, photo names), in one binary
// file written atomically (temp file + rename), so an interrupted write never replaces a good checkpoint.
//
// Layout (little-endian): magic "LGCKPT02" ("LGCKPT01" files, without the sky residuals, still load); then
// length-prefixed fields in the order of save_checkpoint;
// then the end marker "LGCKEND1", so a truncated file is recognised.
#include <string>

#include "lumigauss/train/trainer.h"

namespace lumigauss {

void save_checkpoint(const std::string& path, const TrainState& state);

// Throws Error naming the file if it is missing, not a checkpoint, truncated or inconsistent.
TrainState load_checkpoint(const std::string& path);

}  // namespace lumigauss
