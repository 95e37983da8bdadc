// The COLMAP layout: sparse/0 (or sparse) + images/ [+ masks/] [+ sky_masks/] [+ *split.csv].
#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include "lumigauss/io/colmap.h"
#include "lumigauss/io/dataset_detail.h"
#include "lumigauss/io/lens_distortion.h"
#include "lumigauss/io/split_file.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/util/error.h"

namespace lumigauss::dataset_detail {

namespace fs = std::filesystem;

namespace {

// COLMAP writes its first reconstruction to sparse/0; some tools put the model straight into sparse/.
std::string find_sparse_dir(const std::string& root) {
    for (const char* sub : {"sparse/0", "sparse"}) {
        const std::string dir = (fs::path(root) / sub).string();
        if (find_colmap_format(dir)) return dir;
    }
    return {};
}

// Intrinsics of the pinhole camera and the lens distortion of a COLMAP camera (io/lens_distortion.h: the
// photos are undistorted onto that pinhole when they are loaded).
Camera pinhole_camera(const ColmapCamera& c, const std::string& file, LensDistortion& lens) {
    Camera cam;
    cam.width = c.width, cam.height = c.height;
    const auto& p = c.params;
    if (!colmap_lens_distortion(c.model, p, lens))
        fail_in_file(file, "camera_id " + std::to_string(c.id) + " uses the " + c.model +
                               " model, which LumiGauss does not undistort (it does SIMPLE_RADIAL, RADIAL, "
                               "OPENCV, FULL_OPENCV and the SIMPLE_RADIAL, RADIAL and OPENCV fisheyes). Run "
                               "`colmap image_undistorter --image_path images "
                               "--input_path sparse/0 --output_path undistorted` and use the `undistorted` "
                               "folder as the scene (copy masks/ and sky_masks/ through the same step)");
    const bool one_focal = c.model == "SIMPLE_PINHOLE" || c.model == "SIMPLE_RADIAL" || c.model == "RADIAL" ||
                           c.model == "SIMPLE_RADIAL_FISHEYE" || c.model == "RADIAL_FISHEYE";
    if (one_focal)
        cam.fx = cam.fy = p[0], cam.cx = p[1], cam.cy = p[2];
    else
        cam.fx = p[0], cam.fy = p[1], cam.cx = p[2], cam.cy = p[3];
    if (!(cam.fx > 0 && cam.fy > 0))
        fail_in_file(file, "camera_id " + std::to_string(c.id) + ": focal length must be positive");
    return cam;
}

Camera posed_camera(Camera cam, const ColmapImage& im) {
    cam.rotation = rotation_from_unit_quaternion(normalize_quaternion(im.qvec));
    cam.translation = im.tvec;
    return cam;
}

// masks/a/b.<image extension>, or COLMAP's masks/a/b.jpg.png; "" if neither exists. `masks` maps a path
// relative to the masks folder, without its extension, to the file (index_images_by_stem).
std::string find_mask(const std::map<std::string, std::string>& masks, const std::string& name) {
    const std::string without_ext = (fs::path(name).parent_path() / fs::path(name).stem()).generic_string();
    for (const std::string& key : {without_ext, fs::path(name).generic_string()}) {
        const auto it = masks.find(key);
        if (it != masks.end()) return it->second;
    }
    return {};
}

// The one `*split.csv` at the root, or "".
std::string find_split_file(const std::string& root) {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(root)) {
        const std::string file = entry.path().filename().string();
        if (entry.is_regular_file() && file.ends_with("split.csv")) found.push_back(entry.path().string());
    }
    if (found.size() > 1)
        fail_in_file(root, "several split files (" + found[0] + ", " + found[1] + "); keep one");
    return found.empty() ? std::string() : found[0];
}

// Split file if there is one (every image must be listed), else every holdout_every-th image by name is test.
void assign_splits(std::vector<RawView>& views, const std::string& root, int holdout_every) {
    std::sort(views.begin(), views.end(),
              [](const RawView& a, const RawView& b) { return a.view.name < b.view.name; });
    const std::string split_path = find_split_file(root);
    if (split_path.empty()) {
        for (std::size_t i = 0; i < views.size(); ++i)
            views[i].view.split =
                holdout_every > 0 && i % std::size_t(holdout_every) == 0 ? Split::Test : Split::Train;
        return;
    }
    const auto splits = read_split_file(split_path);
    for (RawView& r : views) {
        auto it = splits.find(r.view.name);
        if (it == splits.end()) it = splits.find(fs::path(r.view.name).filename().string());
        if (it == splits.end())
            fail_in_file(split_path, "image " + r.view.name + " is not listed (every image needs a split)");
        r.view.split = it->second;
    }
    // The other way round: a test or validation photo the split file lists but the model lacks (a cut
    // images.txt lost the test views without a word, and the scores changed meaning). A training photo COLMAP
    // could not register is common and stays allowed.
    std::set<std::string> known;
    for (const RawView& r : views)
        known.insert(r.view.name), known.insert(fs::path(r.view.name).filename().string());
    std::vector<std::string> missing;
    for (const auto& [name, split] : splits)
        if (split != Split::Train && !known.count(name)) missing.push_back(name);
    if (!missing.empty()) {
        std::string names;
        for (std::size_t i = 0; i < std::min<std::size_t>(missing.size(), 3); ++i)
            names += (i ? ", " : "") + missing[i];
        fail_in_file(split_path,
                     "lists " + std::to_string(missing.size()) +
                         " test or validation image(s) the COLMAP model does not have (" + names +
                         (missing.size() > 3 ? ", ..." : "") +
                         "): a cut or different images.txt, or the split file of another scene; if "
                         "COLMAP could not register them, remove them from the split file");
    }
}

struct ColmapFiles {
    std::string sparse, cameras_file, images_file, images_dir;
    bool binary = false;
};

ColmapFiles colmap_files(const std::string& root) {
    ColmapFiles f;
    f.sparse = find_sparse_dir(root);
    f.binary = *find_colmap_format(f.sparse) == ColmapFormat::Binary;
    const std::string ext = f.binary ? ".bin" : ".txt";
    f.cameras_file = (fs::path(f.sparse) / ("cameras" + ext)).string();
    f.images_file = (fs::path(f.sparse) / ("images" + ext)).string();
    f.images_dir = (fs::path(root) / "images").string();
    return f;
}

// One view at full resolution, after checking that its image file exists.
RawView colmap_view(const ColmapImage& im, const ColmapCamera& c, const ColmapFiles& files) {
    RawView r;
    r.view.name = im.name;
    r.view.image_path = (fs::path(files.images_dir) / im.name).string();
    std::error_code ec;
    if (!fs::is_regular_file(r.view.image_path, ec))
        fail_in_file(r.view.image_path, "image listed in " + files.images_file + " is missing");
    r.view.camera = posed_camera(pinhole_camera(c, files.cameras_file, r.view.lens), im);
    r.view.camera_model = c.model;
    r.camera_origin = files.cameras_file + " camera_id " + std::to_string(c.id);
    return r;
}

}  // namespace

bool is_colmap_layout(const std::string& root) {
    return !find_sparse_dir(root).empty();
}

RawScene load_colmap_layout(const std::string& root, const DatasetOptions& options) {
    const ColmapFiles files = colmap_files(root);
    // Poses and points only: the 2D observations and tracks were 40 % of a render's start on plaza.
    const ColmapContent content = ColmapContent::PosesAndPoints;
    const ColmapModel model =
        files.binary ? read_colmap_binary(files.sparse, content) : read_colmap_text(files.sparse, content);
    std::error_code ec;
    if (!fs::is_directory(files.images_dir, ec))
        fail_in_file(files.images_dir,
                     "images folder not found (a COLMAP scene has images/ next to sparse/)");
    const auto masks = index_images_by_stem((fs::path(root) / "masks").string());
    const auto sky_masks = index_images_by_stem((fs::path(root) / "sky_masks").string());
    RawScene scene;
    scene.format = files.binary ? "colmap-binary" : "colmap-text";
    for (const ColmapImage& im : model.images) {
        RawView r = colmap_view(im, model.cameras.at(im.camera_id), files);  // the reader checked the id
        r.view.mask_path = find_mask(masks, im.name);
        r.view.sky_mask_path = find_mask(sky_masks, im.name);
        scene.views.push_back(std::move(r));
    }
    assign_splits(scene.views, root, options.holdout_every);
    scene.point_xyz = model.point_xyz;
    scene.point_rgb = model.point_rgb;
    scene.points_path = (fs::path(files.sparse) / (files.binary ? "points3D.bin" : "points3D.txt")).string();
    return scene;
}

}  // namespace lumigauss::dataset_detail
