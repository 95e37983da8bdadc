#include "lumigauss/io/dataset.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <tuple>

#include "lumigauss/io/dataset_detail.h"
#include "lumigauss/io/image_orientation.h"
#include "lumigauss/io/scene_extent.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

using dataset_detail::RawView;

std::string size_text(int w, int h) {
    return std::to_string(w) + "x" + std::to_string(h);
}

// Header-only checks: the image is readable and as large as its camera says; the mask as large as the image.
// A photo smaller than its camera by one factor on both sides (to a pixel of rounding): a downscaled copy
// of the photos (an images_2/ folder put in place of images/), which nerfstudio and gsplat accept.
bool same_aspect_smaller(int width, int height, const Camera& camera) {
    if (width >= camera.width || height >= camera.height) return false;
    const double expected_height = double(width) * camera.height / camera.width;
    const double expected_width = double(height) * camera.width / camera.height;
    return std::abs(expected_height - height) <= 1.0 && std::abs(expected_width - width) <= 1.0;
}

bool fits_camera(int width, int height, const Camera& camera) {
    return (width == camera.width && height == camera.height) || same_aspect_smaller(width, height, camera);
}

// The orientation the photo's pixels are used in: as stored (COLMAP's way, whatever the tag says) unless only
// the upright photo fits the camera.
int orientation_to_apply(const ImageInfo& stored, const View& v) {
    if (!orientation_swaps_axes(v.exif.orientation) || fits_camera(stored.width, stored.height, v.camera))
        return 1;
    return fits_camera(stored.height, stored.width, v.camera) ? v.exif.orientation : 1;
}

// A mask made from the stored photo is turned with it; one of the upright photo's size is used as it is.
int mask_orientation_for(const ImageInfo& mask, const ImageInfo& stored, int image_orientation) {
    if (image_orientation == 1 || mask.width != stored.width || mask.height != stored.height) return 1;
    return image_orientation;
}

ImageInfo upright_info(ImageInfo info, int orientation) {
    if (orientation_swaps_axes(orientation)) std::swap(info.width, info.height);
    return info;
}

// Checks the files of a view and reads its EXIF; returns true when its camera was scaled to a smaller photo.
bool check_files(RawView& raw) {
    View& v = raw.view;
    const ImageInfo stored = read_image_info(v.image_path);
    v.exif = read_photo_exif(v.image_path);
    v.image_orientation = orientation_to_apply(stored, v);
    const ImageInfo image = upright_info(stored, v.image_orientation);
    bool fitted = false;
    if (same_aspect_smaller(image.width, image.height, v.camera)) {
        v.camera = v.camera.resized(image.width, image.height);
        fitted = true;
    }
    if (image.width != v.camera.width || image.height != v.camera.height)
        fail_in_file(v.image_path,
                     "image is " + size_text(image.width, image.height) +
                         (v.image_orientation != 1 ? " once turned upright by its EXIF orientation" : "") +
                         " but its camera (" + raw.camera_origin + ") is " +
                         size_text(v.camera.width, v.camera.height));
    for (auto [path, kind, orientation] :
         {std::tuple{v.mask_path, "mask", &v.mask_orientation},
          std::tuple{v.sky_mask_path, "sky mask", &v.sky_mask_orientation}}) {
        if (path.empty()) continue;
        const ImageInfo stored_mask = read_image_info(path);
        *orientation = mask_orientation_for(stored_mask, stored, v.image_orientation);
        const ImageInfo mask = upright_info(stored_mask, *orientation);
        if (mask.width != image.width || mask.height != image.height)
            fail_in_file(path, std::string(kind) + " is " + size_text(mask.width, mask.height) +
                                   " but its image " + v.image_path + " is " +
                                   size_text(image.width, image.height));
    }
    return fitted;
}

void check_unique_names(const std::vector<RawView>& views) {
    std::set<std::string> seen;
    for (const RawView& r : views)
        if (!seen.insert(r.view.name).second)
            fail_in_file(r.view.image_path, "two views are named " + r.view.name + " (names must be unique)");
}

// Full-resolution file size must match the camera before anything is downscaled.
View finish_view(RawView raw, int factor, Dataset& d) {
    if (check_files(raw)) ++d.cameras_fitted_to_photos;
    View v = raw.view;
    if (v.image_orientation != 1)
        ++d.photos_turned_upright;
    else if (v.exif.orientation != 1)
        ++d.orientation_tags_not_applied;
    v.source_width = v.camera.width;
    v.source_height = v.camera.height;
    v.camera =
        v.camera.resized(downscaled_size(v.camera.width, factor), downscaled_size(v.camera.height, factor));
    return v;
}

// The loaded image at the view's resolution, after checking that the file has the size its header had:
// undistorted at the photo's resolution, then downscaled.
Image fit_to_view(Image image, int orientation, const View& view, const std::string& path, const char* kind) {
    if (orientation != 1) image = upright_image(image, orientation);
    if (image.width != view.source_width || image.height != view.source_height)
        fail_in_file(path, std::string(kind) + " is " + size_text(image.width, image.height) + " but " +
                               view.name + " needs " + size_text(view.source_width, view.source_height));
    if (!view.lens.is_identity())
        image = undistort_image(image, view.camera.resized(view.source_width, view.source_height), view.lens);
    if (image.width == view.camera.width && image.height == view.camera.height) return image;
    return resize_area(image, view.camera.width, view.camera.height);
}

}  // namespace

const char* split_name(Split split) {
    switch (split) {
        case Split::Train:
            return "train";
        case Split::Test:
            return "test";
        case Split::Validation:
            return "validation";
    }
    return "?";
}

int downscaled_size(int size, int factor) {
    return std::max(1, size / factor);
}

Image Dataset::load_image(const View& view) const {
    return fit_to_view(to_channels(read_image(view.image_path), 3), view.image_orientation, view,
                       view.image_path, "image");
}

Image Dataset::load_mask(const View& view) const {
    // Without a mask file every pixel counts that the (undistorted) photo covers.
    if (view.mask_path.empty())
        return view.lens.is_identity() ? Image(view.camera.width, view.camera.height, 1, 1.0f)
                                       : load_coverage(view);
    return fit_to_view(to_channels(read_image(view.mask_path), 1), view.mask_orientation, view,
                       view.mask_path, "mask");
}

Image Dataset::load_sky_mask(const View& view) const {
    if (view.sky_mask_path.empty()) return Image();
    return fit_to_view(to_channels(read_image(view.sky_mask_path), 1), view.sky_mask_orientation, view,
                       view.sky_mask_path, "sky mask");
}

Image Dataset::load_coverage(const View& view) const {
    if (view.lens.is_identity()) return Image();
    const Image valid =
        undistort_validity(view.camera.resized(view.source_width, view.source_height), view.lens);
    if (valid.width == view.camera.width && valid.height == view.camera.height) return valid;
    return resize_area(valid, view.camera.width, view.camera.height);
}

bool Dataset::has_sky_masks() const {
    return std::any_of(views.begin(), views.end(), [](const View& v) { return !v.sky_mask_path.empty(); });
}

std::size_t Dataset::undistorted_views() const {
    return std::size_t(
        std::count_if(views.begin(), views.end(), [](const View& v) { return !v.lens.is_identity(); }));
}

std::vector<const View*> Dataset::split(Split which) const {
    std::vector<const View*> out;
    for (const View& v : views)
        if (v.split == which) out.push_back(&v);
    return out;
}

namespace {

// Drops the SfM points farther than kFarPointRadii x the cameras' extent (scene_extent.h) from their centroid
// (a point at 1e20 from a bad triangulation overflowed the initial surfel scale at iteration 1).
void drop_far_points(Dataset& d) {
    if (d.views.empty() || d.point_xyz.empty()) return;
    const CameraExtent cameras = camera_extent(d.views);
    if (!(cameras.radius > 0)) return;  // one camera (or all at one place): no scale to judge by
    d.far_point_limit = kFarPointRadii * cameras.radius;
    const Vec3d centroid = cameras.center;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < d.point_xyz.size(); ++i) {
        const Vec3f& p = d.point_xyz[i];
        if (length(Vec3d{p.x, p.y, p.z} - centroid) > d.far_point_limit) continue;
        d.point_xyz[kept] = p, d.point_rgb[kept] = d.point_rgb[i], ++kept;
    }
    d.far_points_dropped = d.point_xyz.size() - kept;
    d.point_xyz.resize(kept), d.point_rgb.resize(kept);
}

}  // namespace

Dataset load_dataset(const std::string& root, const DatasetOptions& options) {
    const int f = options.downscale;
    if (f != 1 && f != 2 && f != 4 && f != 8)
        throw Error("downscale factor must be 1, 2, 4 or 8, not " + std::to_string(f));
    std::error_code ec;
    if (!std::filesystem::is_directory(root, ec)) fail_in_file(root, "scene folder not found");
    dataset_detail::RawScene raw;
    if (dataset_detail::is_colmap_layout(root))
        raw = dataset_detail::load_colmap_layout(root, options);
    else if (dataset_detail::is_nerfosr_layout(root))
        raw = dataset_detail::load_nerfosr_layout(root);
    else
        fail_in_file(root,
                     "not a scene: expected a COLMAP layout (sparse/0/ with cameras, images, points3D as "
                     ".bin or .txt, and images/) or a NeRF-OSR layout (final/{train,validation,test}/rgb/)");
    std::sort(raw.views.begin(), raw.views.end(),
              [](const RawView& a, const RawView& b) { return a.view.name < b.view.name; });
    if (options.test_every) {
        if (*options.test_every < 0) throw Error("--test-every must be 0 (no test photo) or more");
        const auto n = std::size_t(*options.test_every);
        for (std::size_t i = 0; i < raw.views.size(); ++i)
            raw.views[i].view.split = n > 0 && i % n == 0 ? Split::Test : Split::Train;
    }
    check_unique_names(raw.views);
    Dataset d;
    d.root = root;
    d.format = raw.format;
    d.downscale = f;
    d.point_xyz = std::move(raw.point_xyz);
    d.point_rgb = std::move(raw.point_rgb);
    d.points_path = std::move(raw.points_path);
    d.views.reserve(raw.views.size());
    for (const RawView& r : raw.views) d.views.push_back(finish_view(r, f, d));
    drop_far_points(d);
    return d;
}

}  // namespace lumigauss
