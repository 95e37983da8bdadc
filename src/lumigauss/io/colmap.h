#pragma once
// COLMAP sparse models (`sparse/0`), binary and text, as documented in COLMAP's "Output Format" page.
// The model holds what a sparse reconstruction holds: cameras, image poses, SfM point positions and colours,
// and (optional: empty in models made from cameras alone) each image's 2D observations and each point's
// reprojection error and track, so that a model read and written again is still a valid SfM model.
#include <cstdint>
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

// One 2D observation (a keypoint) of an image. On disk COLMAP names the point by its POINT3D_ID; in memory
// it is the point's position in ColmapModel's point arrays, so that ids need not be contiguous on disk.
struct ColmapObservation {
    Vec2<double> xy{};              // pixels, origin at the top-left corner of the top-left pixel
    std::int64_t point_index = -1;  // index into the model's points, -1 when it belongs to none

    bool operator==(const ColmapObservation& o) const {
        return xy.x == o.xy.x && xy.y == o.xy.y && point_index == o.point_index;
    }
};

// One element of a point's track: the image (by IMAGE_ID) and the index of the observation in that image's
// observations (POINT2D_IDX).
struct ColmapTrackElement {
    int image_id = 0;
    int observation = 0;

    bool operator==(const ColmapTrackElement&) const = default;
};

struct ColmapImage {
    int id = 0;
    std::string name;               // path relative to the images folder
    Vec4<double> qvec{1, 0, 0, 0};  // world-to-camera rotation (w, x, y, z), stored w-first in .x .y .z .w
    Vec3d tvec{};                   // world-to-camera translation
    int camera_id = 0;
    std::vector<ColmapObservation> observations;  // POINTS2D[]; empty when the model has none
};

struct ColmapModel {
    std::map<int, ColmapCamera> cameras;
    std::vector<ColmapImage> images;  // in file order
    std::vector<Vec3f> point_xyz;
    std::vector<Vec3f> point_rgb;  // 0..1 (the stored 8-bit colour / 255)
    // Optional, parallel to point_xyz when not empty (else the writers write an error of 0 and empty tracks).
    std::vector<double> point_error;                            // RMS reprojection error, pixels
    std::vector<std::vector<ColmapTrackElement>> point_tracks;  // the observations of each point
};

// COLMAP's camera models: id, name and number of parameters (-1 / empty / -1 when unknown).
int colmap_model_id(const std::string& name);
std::string colmap_model_name(int id);
int colmap_model_num_params(const std::string& name);

enum class ColmapFormat { Binary, Text };

// Which model files `dir` holds: the binary form when cameras.bin, images.bin and points3D.bin are all there
// (COLMAP's own preference), else the text form, else nullopt.
std::optional<ColmapFormat> find_colmap_format(const std::string& dir);

// What to read of a model. The images' 2D observations and the points' tracks and errors are most of a
// large model's bytes, and loading a scene to train, render or evaluate uses none of them: PosesAndPoints
// leaves them empty (and does not check them: a file whose only fault is in them reads).
enum class ColmapContent { Everything, PosesAndPoints };

// Reads `dir`/{cameras,images,points3D}.{bin,txt}. Throws Error naming the file and the record or line for
// a missing or truncated file, a malformed line, an unknown camera model, a parameter count that does not
// match the model, a non-finite pose, or an image whose camera id is not in cameras. An observation whose
// POINT3D_ID is not in points3D (a model edited by hand) reads as belonging to no point.
ColmapModel read_colmap_binary(const std::string& dir, ColmapContent content = ColmapContent::Everything);
ColmapModel read_colmap_text(const std::string& dir, ColmapContent content = ColmapContent::Everything);
// By find_colmap_format; Error naming `dir` if neither.
ColmapModel read_colmap(const std::string& dir, ColmapContent content = ColmapContent::Everything);

// Writes the three files into `dir` (created if missing), each atomically. Numbers are written in the
// shortest form that reads back to the same value, so reading back gives identical records; colours are
// rounded to 8 bit. Points are numbered from 1 in order. Throws Error when the optional arrays are neither
// empty nor as long as point_xyz, or an observation names a point the model does not have.
void write_colmap_text(const std::string& dir, const ColmapModel& model);
void write_colmap_binary(const std::string& dir, const ColmapModel& model);

}  // namespace lumigauss
