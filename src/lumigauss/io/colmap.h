#pragma once
// COLMAP sparse models (`sparse/0`), binary and text, as documented in COLMAP's "Output Format" page.
// The model keeps what LumiGauss needs: cameras, image poses, SfM point positions and colours. 2D
// observations and point tracks are read (and validated) but not kept; the writers write none.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/math/vec.h"

namespace lumigauss {

struct ColmapCamera {
    int id = 0;
    std::string model;  // COLMAP model name, e.g. "PINHOLE"
    int width = 0, height = 0;
    std::vector<double> params;  // in COLMAP's order for the model

    bool operator==(const ColmapCamera&) const = default;
};

struct ColmapImage {
    int id = 0;
    std::string name;               // path relative to the images folder
    Vec4<double> qvec{1, 0, 0, 0};  // world-to-camera rotation (w, x, y, z), stored w-first in .x .y .z .w
    Vec3d tvec{};                   // world-to-camera translation
    int camera_id = 0;
};

struct ColmapModel {
    std::map<int, ColmapCamera> cameras;
    std::vector<ColmapImage> images;  // in file order
    std::vector<Vec3f> point_xyz;
    std::vector<Vec3f> point_rgb;  // 0..1 (the stored 8-bit colour / 255)
};

// COLMAP's camera models: id, name and number of parameters (-1 / empty / -1 when unknown).
int colmap_model_id(const std::string& name);
std::string colmap_model_name(int id);
int colmap_model_num_params(const std::string& name);

enum class ColmapFormat { Binary, Text };

// Which model files `dir` holds: the binary form when cameras.bin, images.bin and points3D.bin are all there
// (COLMAP's own preference), else the text form, else nullopt.
std::optional<ColmapFormat> find_colmap_format(const std::string& dir);

// Reads `dir`/{cameras,images,points3D}.{bin,txt}. Throws Error naming the file and the record or line for
// a missing or truncated file, a malformed line, an unknown camera model, a parameter count that does not
// match the model, a non-finite pose, or an image whose camera id is not in cameras.
ColmapModel read_colmap_binary(const std::string& dir);
ColmapModel read_colmap_text(const std::string& dir);
ColmapModel read_colmap(const std::string& dir);  // by find_colmap_format; Error naming `dir` if neither

// Writes the three files into `dir` (created if missing), each atomically. Doubles are written with 17
// significant digits and floats with 9, so reading back gives identical records; colours are rounded to 8
// bit.
void write_colmap_text(const std::string& dir, const ColmapModel& model);
void write_colmap_binary(const std::string& dir, const ColmapModel& model);

}  // namespace lumigauss
