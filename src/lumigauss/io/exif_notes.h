#pragma once
// What the photos' EXIF meant for a loaded scene, in sentences for `info` and `train` to print: photos turned
// upright, orientation tags left unapplied, the range of exposures, and EXIF blocks that could not be read.
#include <string>
#include <vector>

#include "lumigauss/io/dataset.h"

namespace lumigauss {

// One sentence per fact worth telling (none for a scene without EXIF).
std::vector<std::string> exif_notes(const Dataset& scene);

}  // namespace lumigauss
