#pragma once
// Internals of load_dataset shared by the layout readers (not part of the public API).
#include <map>
#include <string>
#include <vector>

#include "lumigauss/io/dataset.h"

namespace lumigauss::dataset_detail {

// A view at full resolution as a layout reader found it; `camera_origin` says where its camera came from
// ("cameras.txt camera_id 3", a pose file) for messages about size mismatches.
struct RawView {
    View view;
    std::string camera_origin;
};

struct RawScene {
    std::string format;
    std::vector<RawView> views;
    std::vector<Vec3f> point_xyz, point_rgb;
    std::string points_path;  // Dataset::points_path
};

// True when the folder holds the layout; the loaders throw Error for anything missing inside it.
bool is_colmap_layout(const std::string& root);
bool is_nerfosr_layout(const std::string& root);
RawScene load_colmap_layout(const std::string& root, const DatasetOptions& options);
RawScene load_nerfosr_layout(const std::string& root);

// The image files under `dir` (recursively), keyed by their path relative to `dir` without the extension
// ("a/b" for a/b.png), '/'-separated. Empty if `dir` does not exist.
std::map<std::string, std::string> index_images_by_stem(const std::string& dir);
bool has_image_extension(const std::string& path);

}  // namespace lumigauss::dataset_detail
