// `lumigauss fit-light RUN --camera NAME|pose.json [--image PHOTO] [--scene DIR] [-o sh.txt]`: estimates the
// environment SH of a photo of the scene with the model frozen (relight/light_fit.h) and writes it as an SH
// text file that `render --light`, `export --light` and the viewer read (with the photo's sky residual in
// "#sky" rows when the run learned them, shading/sh_text.h: `render --background sky` draws it).
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/lens_distortion.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/light_fit.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"

namespace lumigauss::cli {
namespace {

namespace fs = std::filesystem;

struct FitLightOptions {
    std::string run, camera, image, scene, mask, out, render, via = "auto";
    int downscale = 1, threads = 0;
    bool unshadowed = false, quiet = false;
    LightFitOptions fit;
};

std::string stem_of(const std::string& path) {
    return fs::path(path).stem().string();
}

// The photo, its camera and its mask, before any downscaling.
struct FitInput {
    Camera camera;
    Image photo, mask;
    std::string photo_path;
};

bool is_camera_json(const std::string& s) {
    const std::string ext = fs::path(s).extension().string();
    return ext == ".json" || ext == ".JSON";
}

// A camera JSON holding one camera, or several of which one is named like the photo.
Camera camera_from_json(const std::string& path, const std::string& photo) {
    const std::vector<NamedCamera> cams = read_camera_json(path);
    if (cams.size() == 1) return cams[0].camera;
    for (const NamedCamera& c : cams)
        if (!photo.empty() && (c.name == stem_of(photo) || c.name == fs::path(photo).filename().string()))
            return c.camera;
    throw Error(path + ": holds " + std::to_string(cams.size()) +
                " cameras and none is named after the photo; give a file with one camera");
}

const View& find_view(const Dataset& scene, const std::string& name) {
    for (const View& v : scene.views)
        if (v.name == name) return v;
    const View* by_stem = nullptr;
    for (const View& v : scene.views)
        if (stem_of(v.name) == name) {
            if (by_stem) throw Error("--camera '" + name + "' matches several images of " + scene.root);
            by_stem = &v;
        }
    if (by_stem) return *by_stem;
    throw Error("--camera '" + name + "': no image of that name in " + scene.root + " (" +
                std::to_string(scene.views.size()) + " images, e.g. " +
                (scene.views.empty() ? std::string("none") : scene.views.front().name) + ")");
}

Image read_mask_file(const std::string& path, int width, int height) {
    Image m = read_image(path);
    Image grey(m.width, m.height, 1);
    for (std::size_t p = 0; p < grey.pixels.size(); ++p)
        grey.pixels[p] = m.pixels[p * std::size_t(m.channels)];
    if (grey.width != width || grey.height != height) {
        if (std::abs(double(grey.width) / grey.height - double(width) / height) > 0.01)
            throw Error(path + ": the mask is " + std::to_string(grey.width) + "x" +
                        std::to_string(grey.height) + ", the photo " + std::to_string(width) + "x" +
                        std::to_string(height));
        grey = resize_area(grey, width, height);
    }
    return grey;
}

FitInput load_input(const FitLightOptions& o) {
    FitInput in;
    LensDistortion lens;  // of the scene's camera; none for a camera JSON
    if (is_camera_json(o.camera)) {
        if (o.image.empty()) throw Error("fit-light: --camera " + o.camera + " needs --image PHOTO");
        in.camera = camera_from_json(o.camera, o.image);
        in.photo_path = o.image;
    } else {
        if (o.scene.empty())
            throw Error("fit-light: --camera '" + o.camera +
                        "' is an image name: give --scene DIR (its cameras), or a camera JSON file");
        const Dataset scene = load_dataset(o.scene, DatasetOptions{});
        const View& view = find_view(scene, o.camera);
        in.camera = view.camera;
        in.photo_path = o.image.empty() ? view.image_path : o.image;
        if (o.image.empty()) {
            // The scene's own photo and mask of that view, undistorted as for training.
            in.photo = scene.load_image(view);
            if (o.mask.empty()) in.mask = scene.load_mask(view);
        }
        lens = view.lens;
    }
    if (in.photo.empty()) in.photo = to_channels(read_image(in.photo_path), 3);
    const Image& p = in.photo;
    if (p.width != in.camera.width || p.height != in.camera.height) {
        const double a = double(p.width) / p.height, b = double(in.camera.width) / in.camera.height;
        if (std::abs(a - b) > 0.01 * b)
            throw Error(in.photo_path + ": the photo is " + std::to_string(p.width) + "x" +
                        std::to_string(p.height) + " but the camera is " + std::to_string(in.camera.width) +
                        "x" + std::to_string(in.camera.height) + " (another aspect ratio)");
        in.camera = in.camera.resized(p.width, p.height);
    }
    if (!o.mask.empty()) in.mask = read_mask_file(o.mask, p.width, p.height);
    if (!o.image.empty() && !lens.is_identity()) {
        // A photo of that camera taken through its lens (io/lens_distortion.h): onto the pinhole, with the
        // pixels it does not cover left out of the fit.
        in.photo = undistort_image(in.photo, in.camera, lens);
        if (!in.mask.empty())
            in.mask = undistort_image(in.mask, in.camera, lens);
        else
            in.mask = undistort_validity(in.camera, lens);
    }
    return in;
}

void downscale_input(FitInput& in, int factor) {
    if (factor <= 1) return;
    const int w = std::max(1, in.photo.width / factor), h = std::max(1, in.photo.height / factor);
    in.photo = resize_area(in.photo, w, h);
    if (!in.mask.empty()) in.mask = resize_area(in.mask, w, h);
    in.camera = in.camera.resized(w, h);
}

void run_fit_light(FitLightOptions o) {
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.threads);
    const auto t0 = std::chrono::steady_clock::now();
    const TrainedRun run = load_run_or_ply(o.run);
    FitInput in = load_input(o);
    downscale_input(in, o.downscale);
    const bool has_network = run.lighting.num_images() > 0;
    if (o.via == "auto") o.via = has_network ? "embedding" : "sh";
    o.fit.variable = o.via == "sh" ? LightVariable::Sh : LightVariable::Embedding;
    o.fit.shadowed = !o.unshadowed;
    const int report_every = std::max(1, o.fit.iterations / 10);
    if (!o.quiet)
        o.fit.progress = [&](int it, double loss, double psnr) {
            if ((it + 1) % report_every == 0)
                std::printf("  iteration %4d/%d  loss %.5f  masked PSNR %.2f dB\n", it + 1, o.fit.iterations,
                            loss, psnr);
        };
    if (!o.quiet)
        std::printf("fit-light: %zu surfels from %s; photo %s at %dx%d; fitting the %s via the %s\n",
                    run.model.size(), o.run.c_str(), in.photo_path.c_str(), in.photo.width, in.photo.height,
                    o.fit.shadowed ? "shadowed render" : "unshadowed render",
                    o.fit.variable == LightVariable::Sh ? "SH coefficients" : "lighting network's embedding");
    const LightFitResult r = fit_light(run, in.camera, in.photo, in.mask, o.fit);
    const std::string out = o.out.empty() ? stem_of(in.photo_path) + "_sh.txt" : o.out;
    write_sh_text(out, r.sh, r.sky_residual ? &*r.sky_residual : nullptr);
    if (!o.render.empty()) {
        const RasterImages<float> img =
            render_with_environment(run.model, in.camera, r.sh.cast<float>(),
                                    o.fit.shadowed ? ShadingMode::Shadowed : ShadingMode::Unshadowed,
                                    RasterBackend::Cpu, run.side_rule);
        write_png(o.render, fitted_colour(run, in.camera, img, 0, r));
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("fit-light: masked PSNR %.2f -> %.2f dB, l+ %.3g; wrote %s%s%s (%.1f s)\n", r.initial_psnr,
                r.final_psnr, r.env_loss, out.c_str(), o.render.empty() ? "" : " and ", o.render.c_str(), s);
    if (r.sky_residual && !o.quiet)
        std::printf(
            "fit-light: the run draws each photo's sky with a residual of its own (%s): the photo's is "
            "written with the light (\"#sky\" rows), so `render --light %s --background sky` draws its "
            "sky%s\n",
            run.paths.sky.c_str(), out.c_str(),
            run.sky_pins_light ? ""
                               : "; the light itself is fitted to the surfels alone (sky_pins_light=false)");
}

}  // namespace

void register_fit_light(CLI::App& app) {
    auto o = std::make_shared<FitLightOptions>();
    CLI::App* cmd = app.add_subcommand(
        "fit-light",
        "Estimate the environment SH of a photo of the scene with the trained model frozen; writes an SH "
        "text file (9 rows R G B, world frame, in the model's units; with the photo's sky residual as '#sky' "
        "rows when the run learned one) for render/export --light");
    cmd->add_option("run", o->run, "training run folder, or a bare relightable PLY (then only --via sh)")
        ->required();
    cmd->add_option("--camera", o->camera,
                    "the photo's camera: an image name of --scene (exact, or without extension), or a camera "
                    "JSON file (cameras/camera_json.h layout) with one camera or one named after the photo")
        ->required();
    cmd->add_option("--image", o->image,
                    "the photo (any size with the camera's aspect ratio); default with an image name: that "
                    "image of --scene, with its mask");
    cmd->add_option("--scene", o->scene, "scene folder whose cameras --camera names");
    cmd->add_option("--mask", o->mask, "only pixels where this image is > 0 count (soft values weight them)");
    cmd->add_option("-o,--output", o->out, "SH text file to write (default: PHOTO_STEM_sh.txt)");
    cmd->add_option("--render", o->render, "also write the photo re-rendered under the fitted light (PNG)");
    cmd->add_option("--via", o->via,
                    "what is optimised: sh (the 27 coefficients), embedding (a new embedding through the "
                    "run's lighting network: stays among lights seen in training), auto (embedding when "
                    "the run has a network, else sh)")
        ->check(CLI::IsMember({"auto", "sh", "embedding"}))
        ->capture_default_str();
    cmd->add_flag("--unshadowed", o->unshadowed, "fit the unshadowed render instead of the shadowed one");
    cmd->add_option("--iterations", o->fit.iterations, "Adam iterations")
        ->check(CLI::Range(1, 1000000))
        ->capture_default_str();
    cmd->add_option("-r,--resolution,--downscale", o->downscale,
                    "fit at 1/1, 1/2, 1/4 or 1/8 of the photo's resolution")
        ->check(CLI::IsMember({1, 2, 4, 8}))
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)");
    cmd->add_flag("-q,--quiet", o->quiet, "print only the final line");
    cmd->callback([o] { run_fit_light(*o); });
}

}  // namespace lumigauss::cli
