// The NeRF-OSR layout (research/nerfosr_protocol_and_data.md section 1):
//   final/{train,validation,test}/rgb/<stem>.<jpg|JPG|png>, pose/<stem>.txt, intrinsics/<stem>.txt,
//   [mask/<stem>.png]  (255 = static scene, 0 = transient; the test split may have none),
//   [sky_mask/<stem>.png] (255 = sky; ours, not NeRF-OSR's: e.g. from the published segmentations).
// pose/<stem>.txt: 16 numbers, a row-major 4x4 camera-to-world matrix with OpenCV camera axes (x right, y
// down, z forward), written by NeRF-OSR's cvt.py as the inverse of COLMAP's world-to-camera with no axis
// flip. We assume exactly that: R_w2c = R_c2w^T, t_w2c = -R_c2w^T C (C = last column), no axis change, the
// world (NeRF++-normalised COLMAP world, y roughly down) kept as is. 12 numbers (3x4) are accepted too. The
// rotation must be proper (det +1): a reflected pose mirrors the scene, which no camera can see.
// intrinsics/<stem>.txt: 16 numbers, a 4x4 whose top-left 3x3 is K (9 numbers, a bare K, are accepted too);
// fx = K00, fy = K11, cx = K02, cy = K12. NeRF-OSR casts rays through pixel centres (u + 0.5, v + 0.5) with
// inv(K), which is our Camera convention, so K is used unchanged. Image sizes come from the rgb files.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "lumigauss/io/dataset_detail.h"
#include "lumigauss/io/ply.h"
#include "lumigauss/util/error.h"

namespace lumigauss::dataset_detail {

namespace fs = std::filesystem;

namespace {

constexpr struct {
    const char* folder;
    Split split;
} kSplits[] = {{"train", Split::Train}, {"validation", Split::Validation}, {"test", Split::Test}};

// The folder that holds the split folders: <root>/final or <root> itself.
std::string find_final_dir(const std::string& root) {
    std::error_code ec;
    for (const fs::path& dir : {fs::path(root) / "final", fs::path(root)})
        for (const auto& s : kSplits)
            if (fs::is_directory(dir / s.folder / "rgb", ec)) return dir.string();
    return {};
}

// All numbers of a small text matrix file; Error naming the file unless there are `n` or `alt_n`, all finite.
std::vector<double> read_matrix_file(const std::string& path, std::size_t n, std::size_t alt_n) {
    std::ifstream in(path);
    if (!in) fail_in_file(path, "file not found");
    std::vector<double> values;
    std::string token;
    while (in >> token) {
        double v = 0;
        const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
        if (ec != std::errc() || end != token.data() + token.size())
            fail_in_file(path, "expected a number, found '" + token + "'");
        if (!std::isfinite(v)) fail_in_file(path, "matrix has a NaN or Inf value");
        values.push_back(v);
    }
    if (values.size() != n && values.size() != alt_n)
        fail_in_file(path, "expected " + std::to_string(n) + " numbers (a row-major matrix), found " +
                               std::to_string(values.size()));
    return values;
}

// World-to-camera pose from a row-major c2w (4 values per row either way; the 4th row, if any, is ignored).
void set_pose_from_c2w(Camera& cam, const std::vector<double>& m, const std::string& path) {
    Mat3d r_c2w;
    Vec3d centre;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) r_c2w(i, j) = m[std::size_t(4 * i + j)];
        centre[i] = m[std::size_t(4 * i + 3)];
    }
    const Mat3d should_be_identity = transpose(r_c2w) * r_c2w;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (std::abs(should_be_identity(i, j) - (i == j ? 1.0 : 0.0)) > 1e-3)
                fail_in_file(path, "the rotation part of the camera-to-world pose is not orthonormal");
    const Mat3d& r = r_c2w;
    const double det = r(0, 0) * (r(1, 1) * r(2, 2) - r(1, 2) * r(2, 1)) -
                       r(0, 1) * (r(1, 0) * r(2, 2) - r(1, 2) * r(2, 0)) +
                       r(0, 2) * (r(1, 0) * r(2, 1) - r(1, 1) * r(2, 0));
    if (det < 0)
        fail_in_file(path, "the rotation part of the camera-to-world pose is a reflection (determinant -1)");
    cam.rotation = transpose(r_c2w);
    cam.translation = -(cam.rotation * centre);
}

void set_intrinsics(Camera& cam, const std::vector<double>& k, const std::string& path) {
    const std::size_t row = k.size() == 16 ? 4 : 3;  // 4x4 padded K or a bare 3x3
    cam.fx = k[0], cam.cx = k[2], cam.fy = k[row + 1], cam.cy = k[row + 2];
    if (!(cam.fx > 0 && cam.fy > 0)) fail_in_file(path, "focal lengths K00, K11 must be positive");
    if (std::abs(k[1]) > 1e-9 * cam.fx) fail_in_file(path, "skewed intrinsics (K01 != 0) are not supported");
}

void add_split(const fs::path& split_dir, Split split, RawScene& scene) {
    const auto masks = index_images_by_stem((split_dir / "mask").string());
    const auto sky_masks = index_images_by_stem((split_dir / "sky_mask").string());
    std::vector<fs::path> images;
    for (const auto& entry : fs::directory_iterator(split_dir / "rgb"))
        if (entry.is_regular_file() && has_image_extension(entry.path().string()))
            images.push_back(entry.path());
    for (const fs::path& image : images) {
        const std::string stem = image.stem().string();
        const std::string pose_path = (split_dir / "pose" / (stem + ".txt")).string();
        const std::string k_path = (split_dir / "intrinsics" / (stem + ".txt")).string();
        RawView r;
        r.view.name = image.filename().string();
        r.view.image_path = image.string();
        r.view.split = split;
        const auto mask = masks.find(stem);
        if (mask != masks.end()) r.view.mask_path = mask->second;
        const auto sky_mask = sky_masks.find(stem);
        if (sky_mask != sky_masks.end()) r.view.sky_mask_path = sky_mask->second;
        const ImageInfo info = read_image_info(r.view.image_path);
        r.view.camera.width = info.width, r.view.camera.height = info.height;
        set_intrinsics(r.view.camera, read_matrix_file(k_path, 16, 9), k_path);
        set_pose_from_c2w(r.view.camera, read_matrix_file(pose_path, 16, 12), pose_path);
        r.view.camera_model = "NERF-OSR K";
        r.camera_origin = k_path;
        scene.views.push_back(std::move(r));
    }
}

// SfM points from a PLY of vertices x, y, z and optional red, green, blue (0..255 as integers, or 0..1).
void read_points_ply(const std::string& path, RawScene& scene) {
    const PlyVertexTable table = read_ply_vertices(path);
    if (table.count == 0) fail_in_file(path, "the point cloud has no points");
    const auto& x = table.column("x", path);
    const auto& y = table.column("y", path);
    const auto& z = table.column("z", path);
    const bool rgb = table.has("red") && table.has("green") && table.has("blue");
    float rgb_max = 0;
    if (rgb)
        for (const char* c : {"red", "green", "blue"})
            for (float v : table.column(c, path)) rgb_max = std::max(rgb_max, v);
    const float rgb_scale = rgb_max > 1 ? 1.0f / 255.0f : 1.0f;
    for (std::size_t i = 0; i < table.count; ++i) {
        const Vec3f p{x[i], y[i], z[i]};
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
            fail_in_file(path, "point " + std::to_string(i) + " has a NaN or Inf coordinate");
        scene.point_xyz.push_back(p);
        scene.point_rgb.push_back(rgb ? Vec3f{table.column("red", path)[i], table.column("green", path)[i],
                                              table.column("blue", path)[i]} *
                                            rgb_scale
                                      : Vec3f{0.5f, 0.5f, 0.5f});
    }
}

}  // namespace

bool is_nerfosr_layout(const std::string& root) {
    return !find_final_dir(root).empty();
}

RawScene load_nerfosr_layout(const std::string& root) {
    const fs::path final_dir = find_final_dir(root);
    RawScene scene;
    scene.format = "nerf-osr";
    std::error_code ec;
    for (const auto& s : kSplits)
        if (fs::is_directory(final_dir / s.folder / "rgb", ec))
            add_split(final_dir / s.folder, s.split, scene);
    scene.points_path = (final_dir / "points3d.ply").string();
    if (fs::is_regular_file(scene.points_path, ec)) read_points_ply(scene.points_path, scene);
    return scene;
}

}  // namespace lumigauss::dataset_detail
