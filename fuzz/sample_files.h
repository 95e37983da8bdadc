#pragma once
// Small valid objects for the seeds: what the project's writers turn into the files the targets parse.
#include <string>

#include "fuzz_target.h"
#include "lumigauss/io/colmap.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss::fuzz {

ColmapModel sample_colmap_model();  // two cameras, three images, four points
SurfelModel sample_surfel_model();  // three surfels
void make_folder(const std::string& dir);

// A COLMAP model's three files (cameras, images, points3D; .txt or .bin by `extension`) as one input: the
// seed written by the project's writer, and the parse of an input by the matching reader.
std::string colmap_seed(const std::string& extension);
void parse_colmap_parts(Bytes input, const std::string& extension);

}  // namespace lumigauss::fuzz
