#include "lumigauss/io/colmap.h"

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <unordered_map>

#include "lumigauss/io/colmap_detail.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

struct ModelInfo {
    int id;
    const char* name;
    int num_params;
};

// COLMAP's src/colmap/sensor/models.h: the ids are what cameras.bin stores.
constexpr std::array<ModelInfo, 12> kModels{{{0, "SIMPLE_PINHOLE", 3},
                                             {1, "PINHOLE", 4},
                                             {2, "SIMPLE_RADIAL", 4},
                                             {3, "RADIAL", 5},
                                             {4, "OPENCV", 8},
                                             {5, "OPENCV_FISHEYE", 8},
                                             {6, "FULL_OPENCV", 12},
                                             {7, "FOV", 5},
                                             {8, "SIMPLE_RADIAL_FISHEYE", 4},
                                             {9, "RADIAL_FISHEYE", 5},
                                             {10, "THIN_PRISM_FISHEYE", 12},
                                             {11, "RAD_TAN_THIN_PRISM_FISHEYE", 16}}};

bool has_all(const std::string& dir, const char* ext) {
    std::error_code ec;
    for (const char* stem : {"cameras", "images", "points3D"})
        if (!std::filesystem::is_regular_file(colmap_detail::join(dir, (std::string(stem) + ext).c_str()),
                                              ec))
            return false;
    return true;
}

}  // namespace

int colmap_model_id(const std::string& name) {
    for (const ModelInfo& m : kModels)
        if (name == m.name) return m.id;
    return -1;
}

std::string colmap_model_name(int id) {
    for (const ModelInfo& m : kModels)
        if (id == m.id) return m.name;
    return {};
}

int colmap_model_num_params(const std::string& name) {
    for (const ModelInfo& m : kModels)
        if (name == m.name) return m.num_params;
    return -1;
}

std::optional<ColmapFormat> find_colmap_format(const std::string& dir) {
    if (has_all(dir, ".bin")) return ColmapFormat::Binary;
    if (has_all(dir, ".txt")) return ColmapFormat::Text;
    return std::nullopt;
}

ColmapModel read_colmap(const std::string& dir, ColmapContent content) {
    const auto format = find_colmap_format(dir);
    if (!format)
        fail_in_file(dir, "no COLMAP model here (need cameras, images and points3D, all .bin or all .txt)");
    return *format == ColmapFormat::Binary ? read_colmap_binary(dir, content)
                                           : read_colmap_text(dir, content);
}

namespace colmap_detail {

std::string join(const std::string& dir, const char* file) {
    return (std::filesystem::path(dir) / file).string();
}

std::string read_whole_file(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) fail_in_file(path, "file not found");
    // One read of the known size: a character iterator took 14 instructions per byte, a tenth of a render's
    // start on plaza (11 MB of text).
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) fail_in_file(path, "cannot open the file");
    const std::streamoff size = in.tellg();
    if (size < 0) fail_in_file(path, "cannot tell the file's size");
    std::string content(std::size_t(size), '\0');
    in.seekg(0);
    if (size > 0 && !in.read(content.data(), size)) fail_in_file(path, "read error");
    return content;
}

void check_camera(const ColmapCamera& camera, const std::string& file, const std::string& where) {
    const int expected = colmap_model_num_params(camera.model);
    const std::string id = " (camera_id " + std::to_string(camera.id) + ")";
    if (expected < 0) fail_in_file(file, where + id + ": unknown camera model '" + camera.model + "'");
    if (int(camera.params.size()) != expected)
        fail_in_file(file, where + id + ": camera model " + camera.model + " has " +
                               std::to_string(expected) + " parameters, found " +
                               std::to_string(camera.params.size()));
    if (camera.width <= 0 || camera.height <= 0)
        fail_in_file(file, where + id + ": image size must be positive");
    for (double p : camera.params)
        if (!std::isfinite(p)) fail_in_file(file, where + id + ": non-finite camera parameter");
}

void check_image(const ColmapImage& image, const std::map<int, ColmapCamera>& cameras,
                 const std::string& file, const std::string& where) {
    const std::string what = where + " (image_id " + std::to_string(image.id) + ", " + image.name + ")";
    const Vec4<double> q = image.qvec;
    const Vec3d t = image.tvec;
    for (double v : {q.x, q.y, q.z, q.w, t.x, t.y, t.z})
        if (!std::isfinite(v)) fail_in_file(file, what + ": pose has a NaN or Inf value");
    if (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w < 1e-12)
        fail_in_file(file, what + ": rotation quaternion is zero");
    if (!cameras.contains(image.camera_id))
        fail_in_file(file, what + ": camera_id " + std::to_string(image.camera_id) +
                               " does not exist in the cameras file");
}

void index_observed_points(ColmapModel& model, const std::vector<std::uint64_t>& point_ids) {
    std::unordered_map<std::uint64_t, std::int64_t> index_of;
    index_of.reserve(point_ids.size());
    for (std::size_t i = 0; i < point_ids.size(); ++i) index_of.emplace(point_ids[i], std::int64_t(i));
    for (ColmapImage& image : model.images)
        for (ColmapObservation& o : image.observations) {
            if (o.point_index < 0) continue;  // COLMAP writes -1 for a keypoint without a point
            const auto it = index_of.find(std::uint64_t(o.point_index));
            o.point_index = it == index_of.end() ? -1 : it->second;
        }
}

void check_optional_arrays(const ColmapModel& model, const std::string& dir) {
    const std::size_t n = model.point_xyz.size();
    if (!model.point_error.empty() && model.point_error.size() != n)
        fail_in_file(dir, "point_error holds " + std::to_string(model.point_error.size()) + " values for " +
                              std::to_string(n) + " points");
    if (!model.point_tracks.empty() && model.point_tracks.size() != n)
        fail_in_file(dir, "point_tracks holds " + std::to_string(model.point_tracks.size()) + " tracks for " +
                              std::to_string(n) + " points");
    for (const ColmapImage& image : model.images)
        for (const ColmapObservation& o : image.observations)
            if (o.point_index >= std::int64_t(n))
                fail_in_file(dir, "image " + image.name + " observes point " + std::to_string(o.point_index) +
                                      " of " + std::to_string(n));
}

const std::vector<ColmapTrackElement>& point_track(const ColmapModel& model, std::size_t i) {
    static const std::vector<ColmapTrackElement> kNone;
    return model.point_tracks.empty() ? kNone : model.point_tracks[i];
}

}  // namespace colmap_detail

}  // namespace lumigauss
