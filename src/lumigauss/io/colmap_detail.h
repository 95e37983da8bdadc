#pragma once
// Internals shared by the COLMAP text and binary readers/writers (not part of the public API).
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "lumigauss/io/colmap.h"

namespace lumigauss::colmap_detail {

// `dir`/`file`, with a separator.
std::string join(const std::string& dir, const char* file);

// The whole file, or Error naming it if it cannot be read.
std::string read_whole_file(const std::string& path);

// Checks on one image once it is parsed; `where` locates it in `file` ("line 12", "record 3 (image_id 7)").
void check_image(const ColmapImage& image, const std::map<int, ColmapCamera>& cameras,
                 const std::string& file, const std::string& where);

// A point colour in [0, 1] as COLMAP's 8-bit value (clamped, rounded).
inline std::uint8_t colour_byte(float c) {
    return std::uint8_t(std::lround(std::fmin(std::fmax(c, 0.0f), 1.0f) * 255.0f));
}

// Checks that a camera's model is known and has the right number of parameters.
void check_camera(const ColmapCamera& camera, const std::string& file, const std::string& where);

// After reading: the observations hold the file's POINT3D_IDs in `point_index`; `point_ids` are the ids of
// the points in the order read. Turns each id into the point's index (-1 for an id points3D does not have).
void index_observed_points(ColmapModel& model, const std::vector<std::uint64_t>& point_ids);

// Before writing: throws Error naming `dir` when the optional point arrays are neither empty nor as long as
// point_xyz, or an observation names a point index the model does not have.
void check_optional_arrays(const ColmapModel& model, const std::string& dir);

// The reprojection error to write for point i (0 when the model has none).
inline double point_error(const ColmapModel& model, std::size_t i) {
    return model.point_error.empty() ? 0.0 : model.point_error[i];
}

// The track to write for point i (empty when the model has none).
const std::vector<ColmapTrackElement>& point_track(const ColmapModel& model, std::size_t i);

}  // namespace lumigauss::colmap_detail
