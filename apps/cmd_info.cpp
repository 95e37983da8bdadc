// `lumigauss info <scene> [-r N] [-q]`: what load_dataset sees in a scene folder, before any training.
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "commands.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/exif_notes.h"
#include "lumigauss/io/scene_extent.h"

namespace lumigauss::cli {

namespace {

struct InfoOptions {
    std::string scene;
    int downscale = 1;
    std::string masks = "transient";
    bool quiet = false;
    bool photos = false;
};

// "128x96 (20), 64x48 (3)": distinct values with how many views have each.
std::string counted(const std::map<std::string, int>& counts) {
    std::string out;
    for (const auto& [value, n] : counts)
        out += (out.empty() ? "" : ", ") + value + " (" + std::to_string(n) + ")";
    return out.empty() ? "none" : out;
}

void print_views(const Dataset& d, const std::string& mask_mode) {
    std::printf("views:         %zu (train %zu, test %zu, validation %zu)\n", d.views.size(),
                d.split(Split::Train).size(), d.split(Split::Test).size(), d.split(Split::Validation).size());
    std::map<std::string, int> sizes, models;
    int masks = 0, sky_masks = 0;
    for (const View& v : d.views) {
        ++sizes[std::to_string(v.camera.width) + "x" + std::to_string(v.camera.height)];
        ++models[v.camera_model];
        masks += v.mask_path.empty() ? 0 : 1;
        sky_masks += v.sky_mask_path.empty() ? 0 : 1;
    }
    std::printf("downscale:     %d\nresolutions:   %s\n", d.downscale, counted(sizes).c_str());
    std::printf("camera models: %s\n", counted(models).c_str());
    if (d.undistorted_views() > 0)
        std::printf(
            "lens:          %zu views with lens distortion, undistorted as they load onto the pinhole of "
            "the same intrinsics (pixels the photo does not cover are masked out)\n",
            d.undistorted_views());
    for (const std::string& note : exif_notes(d)) std::printf("exif:          %s\n", note.c_str());
    std::printf("masks:         %d of %zu views", masks, d.views.size());
    if (masks > 0)
        std::printf(", taken as %s\n", mask_mode == "object"
                                           ? "object masks (0 = empty space: nothing may be drawn there)"
                                           : "transient masks (0 = ignore the pixel; train --set "
                                             "mask_mode=object for foreground masks of one object)");
    else
        std::printf("\n");
    std::printf("sky masks:     %d of %zu views%s\n", sky_masks, d.views.size(),
                sky_masks > 0
                    ? " (255 = sky: kept empty, and the sky drawn behind the surfels is fitted to it)"
                    : " (the sky is then found where the drawn sky already matches the photo)");
}

void print_extent(const Dataset& d) {
    if (d.point_xyz.empty())
        std::printf("points:        none (training needs SfM points in %s)\n", d.points_path.c_str());
    else
        std::printf("points:        %zu (%s)\n", d.point_xyz.size(), d.points_path.c_str());
    if (d.cameras_fitted_to_photos > 0)
        std::printf(
            "cameras:       %zu scaled down to their photos (smaller than the COLMAP camera, same "
            "aspect ratio)\n",
            d.cameras_fitted_to_photos);
    if (d.far_points_dropped > 0)
        std::printf("               (%zu more dropped: farther than %.4g from the cameras' centre)\n",
                    d.far_points_dropped, d.far_point_limit);
    const CameraExtent e = camera_extent(d.views);
    std::printf("camera centre: mean (%.4g, %.4g, %.4g), extent %.4g (1.1 x max distance from the mean)\n",
                e.center.x, e.center.y, e.center.z, e.radius);
    const PointBounds b = point_bounds(d.point_xyz);
    if (b.empty) {
        std::printf("points bbox:   none (no SfM points)\n");
        return;
    }
    std::printf("points bbox:   min (%.4g, %.4g, %.4g), max (%.4g, %.4g, %.4g)\n", double(b.min.x),
                double(b.min.y), double(b.min.z), double(b.max.x), double(b.max.y), double(b.max.z));
}

// "1/250 s" below a second, "2.5 s" above, "-" when unknown.
std::string exposure_time(const std::optional<double>& seconds) {
    if (!seconds) return "-";
    char text[32];
    if (*seconds < 1)
        std::snprintf(text, sizeof text, "1/%.4g s", 1.0 / *seconds);
    else
        std::snprintf(text, sizeof text, "%.4g s", *seconds);
    return text;
}

// One line per photo: split, size, what its EXIF said (orientation and whether it was applied, exposure).
void print_photos(const Dataset& d) {
    std::printf("photos:        name, split, size, EXIF orientation, exposure time, f-number, ISO, EV100\n");
    for (const View& v : d.views) {
        const PhotoExif& e = v.exif;
        const auto value = [](const std::optional<double>& x, const char* format) {
            char text[32] = "-";
            if (x) std::snprintf(text, sizeof text, format, *x);
            return std::string(text);
        };
        const std::string orientation =
            e.orientation == 1 ? "1"
                               : std::to_string(e.orientation) +
                                     (v.image_orientation != 1 ? " (turned upright)" : " (as stored)");
        std::printf("  %s  %s  %dx%d  %s  %s  %s  %s  %s%s%s\n", v.name.c_str(), split_name(v.split),
                    v.camera.width, v.camera.height, orientation.c_str(),
                    exposure_time(e.exposure_time_s).c_str(), value(e.f_number, "f/%.3g").c_str(),
                    value(e.iso, "%.6g").c_str(), value(e.ev100(), "%.2f").c_str(),
                    e.problem.empty() ? "" : "  EXIF unreadable: ", e.problem.c_str());
    }
}

void run_info(const InfoOptions& o) {
    DatasetOptions options;
    options.downscale = o.downscale;
    const Dataset d = load_dataset(o.scene, options);
    if (o.quiet) {  // one line, for scripts and logs
        std::printf("info: %s: %s, %zu views (train %zu, test %zu), %zu SfM points\n", d.root.c_str(),
                    d.format.c_str(), d.views.size(), d.split(Split::Train).size(),
                    d.split(Split::Test).size(), d.point_xyz.size());
        return;
    }
    std::printf("scene:         %s\nformat:        %s\n", d.root.c_str(), d.format.c_str());
    print_views(d, o.masks);
    print_extent(d);
    if (o.photos) print_photos(d);
}

}  // namespace

void register_info(CLI::App& app) {
    auto options = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand("info",
                                       "Describe a scene: views per split, resolutions, cameras, masks, "
                                       "SfM points and extent");
    cmd->add_option("scene", options->scene, "Scene folder (COLMAP sparse/0 + images/, or NeRF-OSR final/)")
        ->required();
    cmd->add_option("-r,--resolution,--downscale", options->downscale, "Downscale images by 1, 2, 4 or 8")
        ->check(CLI::IsMember({1, 2, 4, 8}));
    cmd->add_option("--masks", options->masks, "How train takes the masks: transient (default) or object")
        ->check(CLI::IsMember({"transient", "object"}));
    cmd->add_flag("-q,--quiet", options->quiet, "print one summary line");
    cmd->add_flag("--photos", options->photos,
                  "also one line per photo: split, size, EXIF orientation and exposure (EV100)");
    cmd->callback([options] { run_info(*options); });
}

}  // namespace lumigauss::cli
