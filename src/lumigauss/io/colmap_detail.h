#pragma once
// Internals shared by the COLMAP text and binary readers/writers (not part of the public API).
#include <cmath>
#include <cstdint>
#include <map>
#include <string>

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

}  // namespace lumigauss::colmap_detail
