#include "sample_files.h"

#include "fuzz_support.h"

#include <filesystem>
#include <vector>

namespace lumigauss::fuzz {

ColmapModel sample_colmap_model() {
    ColmapModel m;
    m.cameras[1] = {1, "PINHOLE", 64, 48, {60.0, 61.0, 32.0, 24.0}};
    m.cameras[2] = {2, "SIMPLE_PINHOLE", 32, 24, {30.0, 16.0, 12.0}};
    // Observations and tracks too, so that the seeds reach their parsers: points 0 and 1 are seen twice,
    // image a.png has a keypoint without a point.
    m.images.push_back(
        {1, "a.png", {1, 0, 0, 0}, {0, 0, 4}, 1, {{{32, 24}, 0}, {{40.5, 24}, 1}, {{3, 4}, -1}}});
    m.images.push_back({2, "b.png", {0.9238795, 0, 0.3826834, 0}, {0.5, 0, 4}, 1, {{{30.25, 23}, 0}}});
    m.images.push_back({3, "c.png", {0.7071068, 0.7071068, 0, 0}, {0, -1, 3}, 2, {{{16, 12}, 1}}});
    m.point_xyz = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}, {-1, -1, 1}};
    m.point_rgb = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5f, 0.5f, 0.5f}};
    m.point_error = {0.5, 0.25, 0, 0};
    m.point_tracks = {{{1, 0}, {2, 0}}, {{1, 1}, {3, 0}}, {}, {}};
    return m;
}

SurfelModel sample_surfel_model() {
    const std::size_t n = 3;
    std::vector<std::vector<float>> raw;
    for (const ModelParam p : kAllModelParams) {
        std::vector<float> values(n * std::size_t(SurfelModel::width(p)));
        for (std::size_t i = 0; i < values.size(); ++i) values[i] = 0.1f * float(i % 11) - 0.3f;
        if (p == ModelParam::Rotation)
            for (std::size_t i = 0; i < n; ++i) values[4 * i] = 1.0f;
        raw.push_back(std::move(values));
    }
    return SurfelModel::from_raw(std::move(raw));
}

void make_folder(const std::string& dir) {
    std::filesystem::create_directories(dir);
}

namespace {

std::vector<std::string> colmap_files(const std::string& extension) {
    return {"cameras" + extension, "images" + extension, "points3D" + extension};
}

}  // namespace

std::string colmap_seed(const std::string& extension) {
    const std::string dir = scratch_path("seed_colmap" + extension);
    if (extension == ".txt")
        write_colmap_text(dir, sample_colmap_model());
    else
        write_colmap_binary(dir, sample_colmap_model());
    std::vector<std::string> parts;
    for (const std::string& f : colmap_files(extension)) parts.push_back(read_file(dir + "/" + f));
    return join_parts(parts);
}

void parse_colmap_parts(Bytes input, const std::string& extension) {
    const std::string dir = scratch_path("colmap" + extension);
    make_folder(dir);
    const std::vector<std::string> files = colmap_files(extension), parts = split_parts(input, files.size());
    for (std::size_t i = 0; i < files.size(); ++i) write_file(dir + "/" + files[i], parts[i]);
    // Both ways a model is read: whole (tools that write it back), and poses and points alone (load_dataset).
    for (const ColmapContent content : {ColmapContent::Everything, ColmapContent::PosesAndPoints})
        refuse_cleanly([&] {
            (void)(extension == ".txt" ? read_colmap_text(dir, content) : read_colmap_binary(dir, content));
        });
}

}  // namespace lumigauss::fuzz
