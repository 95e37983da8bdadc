#pragma once
// A scene on disk as views (image path, optional mask path, pinhole camera and lens, split) plus SfM
// points. Two layouts are recognised (load_dataset sniffs which):
//   COLMAP:   <root>/sparse/0/ (or <root>/sparse/) with {cameras,images,points3D}.{bin,txt}, <root>/images/,
//             optional <root>/masks/ (mask of images/a/b.jpg: masks/a/b.<any image extension> or
//             masks/a/b.jpg.png, COLMAP's own naming), optional <root>/sky_masks/ (the same naming; 255 =
//             the pixel sees the sky, as a semantic segmentation gives it), optional <root>/*split.csv
//             (`filename;split`).
//   NeRF-OSR: <root>/final/ (or <root> itself) with {train,validation,test}/{rgb,pose,intrinsics,mask}/,
//             optional {train,validation,test}/sky_mask/ and optional points3d.ply (SfM points in the poses'
//             world, vertex x y z [red green blue], as NeuSky's overlay ships them; training needs them).
// Pixels are loaded lazily (load_image, load_mask); load_dataset only checks that every file is there and
// that its header size matches its camera.
//
// Downscaling by a factor f: a W x H image becomes floor(W/f) x floor(H/f) (at least 1), by area averaging of
// the whole source extent onto the whole target extent (resize_area), and the camera is Camera::resized to
// that size, so intrinsics scale by floor(W/f)/W and floor(H/f)/H -- exactly 1/f when f divides the size.
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/lens_distortion.h"
#include "lumigauss/io/photo_exif.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

struct DatasetOptions {
    int downscale = 1;  // 1, 2, 4 or 8
    // Without a split file every n-th image (sorted by name, the first included) is a test image; 0: none.
    int holdout_every = 8;
    // Set (train --test-every N, --no-test): every n-th image by name is a test image and the others train
    // (0: every image trains), whatever the split file or the NeRF-OSR folders say.
    std::optional<int> test_every = std::nullopt;
};

enum class Split { Train, Test, Validation };

const char* split_name(Split split);  // "train", "test", "validation"

struct View {
    std::string name;           // image name as the model gives it (relative to the images folder)
    std::string image_path;     // full path
    std::string mask_path;      // empty if the view has no mask
    std::string sky_mask_path;  // empty if the view has no sky mask
    Camera camera;              // at the loaded (downscaled) resolution
    // Where the pinhole came from: the COLMAP model name, or "NERF-OSR K" for NeRF-OSR.
    std::string camera_model;
    // The photo's lens (COLMAP's SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV); the load_* functions undistort
    // the image and masks onto `camera`, and load_mask is 0 where the photo does not hold the pixel's ray.
    LensDistortion lens;
    Split split = Split::Train;
    int source_width = 0, source_height = 0;  // the camera's size before downscaling (the upright photo's)
    // The photo's EXIF (orientation, exposure; io/photo_exif.h).
    PhotoExif exif;
    // The EXIF orientations the load_* functions apply to the image and mask files (1: the pixels as stored).
    // COLMAP calibrates the stored pixels whatever the tag says, so a photo is turned upright only when its
    // tag swaps width and height and only the upright photo has its camera's size (its poses came from a
    // tool that applied the tag); a mask is turned with it when it has the stored photo's size.
    int image_orientation = 1, mask_orientation = 1, sky_mask_orientation = 1;
};

inline constexpr double kFarPointRadii = 1000.0;

struct Dataset {
    std::string root;
    std::string format;                       // "colmap-binary", "colmap-text" or "nerf-osr"
    std::vector<View> views;                  // sorted by name
    std::vector<Vec3f> point_xyz, point_rgb;  // SfM points (rgb in 0..1); may be empty for NeRF-OSR
    // The file the SfM points come from (COLMAP: sparse/0/points3D.{bin,txt}; NeRF-OSR: final/points3d.ply,
    // which the layout may lack), for messages about them.
    std::string points_path;
    int downscale = 1;
    // SfM points dropped at load for lying absurdly far from the cameras (kFarPointRadii x the cameras'
    // extent about their centroid, io/scene_extent.h): one point at 1e20 made the initial surfel scale
    // overflow.
    std::size_t far_points_dropped = 0;
    // Views whose photo was smaller than its camera with the same aspect ratio (a downscaled copy of the
    // photos): their camera was scaled to the photo (Camera::resized) before any -r downscale.
    std::size_t cameras_fitted_to_photos = 0;
    double far_point_limit = 0;  // the distance from the cameras' centroid beyond which they were dropped
    // Views turned upright by their EXIF orientation (View::image_orientation != 1), and views whose tag
    // says to turn them but whose stored pixels have their camera's size (used as stored, as COLMAP does).
    std::size_t photos_turned_upright = 0, orientation_tags_not_applied = 0;

    // RGB in [0, 1] (gray is replicated, alpha dropped), undistorted (View::lens), resized by the downscale
    // factor. Throws Error naming
    // the file if it cannot be read or its size is not the camera's.
    Image load_image(const View& view) const;
    // One channel in [0, 1] (first channel of the file; 1 = use the pixel), resized like the image. All ones
    // when the view has no mask (except where undistortion leaves the photo: 0 there). Throws Error naming
    // the mask file if its size differs from the image's.
    Image load_mask(const View& view) const;
    // One channel in [0, 1], 1 = sky, resized like the image; an empty image when the view has none. Throws
    // Error naming the file if it cannot be read or its size differs from the image's.
    Image load_sky_mask(const View& view) const;
    // One channel: 1 where the undistorted photo holds the pixel's ray, 0 where it does not (fractions at
    // the edge after downscaling); an empty image for a view without lens distortion (it covers everything).
    Image load_coverage(const View& view) const;
    // True when at least one view has a sky mask.
    bool has_sky_masks() const;
    // How many views have a lens distortion that load_* undistorts.
    std::size_t undistorted_views() const;
    std::vector<const View*> split(Split which) const;
};

// Loads the layout found at `root`; Error naming the file and what to do for anything missing or
// inconsistent.
Dataset load_dataset(const std::string& root, const DatasetOptions& options = {});

// The size an image of `size` pixels has after downscaling by `factor` (see above).
int downscaled_size(int size, int factor);

}  // namespace lumigauss
