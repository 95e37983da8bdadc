#pragma once
// Small valid objects for the seeds: what the project's writers turn into the files the targets parse.
#include <string>

#include "lumigauss/io/colmap.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss::fuzz {

ColmapModel sample_colmap_model();  // two cameras, three images, four points
SurfelModel sample_surfel_model();  // three surfels
void make_folder(const std::string& dir);

}  // namespace lumigauss::fuzz
