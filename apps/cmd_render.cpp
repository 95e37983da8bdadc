// `lumigauss render`, two modes:
//   render RUN --light L [--scene DIR] [--cameras ...]: relights a trained run (relight/relight_job.h);
//   render --ply FILE --scene DIR: renders a surfel PLY in the 2DGS layout from the cameras of a scene, one
//   PNG per view named after its image, so the rasterizer can be checked from outside and 2DGS models
//   trained elsewhere can be rendered.
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>

#include "commands.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/splat_ply.h"
#include "lumigauss/relight/relight_job.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/util/error.h"

namespace lumigauss::cli {
namespace {

struct RenderOptions {
    std::string ply, scene, out = "renders", split = "all";
    int downscale = 0;  // 0: 1 for --ply, the run's training resolution for a run
    int threads = 0;
    std::string backend = "cpu";
    std::string background_text;  // "sky" or "R,G,B"
    std::vector<float> background{0, 0, 0};
    bool background_given = false, sky_background = false, split_given = false, cameras_given = false;
    bool extra_maps = false;
    // Run mode (relight_job.h).
    std::string run, outputs = "all";
    bool no_video = false, quiet = false;
    RelightJob job;
};

std::filesystem::path output_path(const std::string& dir, const std::string& image_name,
                                  const std::string& suffix) {
    std::filesystem::path p = std::filesystem::path(dir) / image_name;
    p.replace_extension();
    p += suffix;
    return p;
}

void write_extra_maps(const RenderOptions& o, const View& v, const RasterImages<float>& img) {
    write_png(output_path(o.out, v.name, "_alpha.png").string(), alpha_image(img));
    write_exr(output_path(o.out, v.name, "_depth.exr").string(), expected_depth(img));
    write_png(output_path(o.out, v.name, "_normal.png").string(), encode_normals(img));
}

void run_relight(const RenderOptions& o, RasterBackend backend) {
    if (o.extra_maps) throw Error("--maps is for --ply; a run's maps are chosen with --outputs");
    if (o.split_given) throw Error("--split is for --ply; a run's cameras are chosen with --cameras");
    RelightJob job = o.job;
    job.run = o.run;
    job.scene = o.scene;
    job.out = o.out;
    job.downscale = o.downscale;
    job.outputs = parse_relit_outputs(o.outputs);
    job.outputs.exr = o.job.outputs.exr;
    job.outputs.has_background = o.background_given && !o.sky_background;
    job.outputs.background = {o.background[0], o.background[1], o.background[2]};
    job.outputs.sky_background = o.sky_background;
    job.video = !o.no_video;
    job.backend = backend;
    const auto t0 = std::chrono::steady_clock::now();
    const RelightSummary summary = run_relight_job(job, [&](const std::string& line) {
        if (!o.quiet) std::printf("%s\n", line.c_str());
    });
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("render: wrote %d frame(s) from %zu camera(s) to %s (%.1f s)\n", summary.frames,
                summary.cameras.size(), o.out.c_str(), s);
}

// --background: "sky" (a run: the light's own sky) or three numbers R,G,B.
void parse_background(RenderOptions& o) {
    if (!o.background_given) return;
    if (o.background_text == "sky") {
        if (o.run.empty())
            throw Error("--background sky is for a run (the sky of its light); --ply takes R,G,B");
        o.sky_background = true;
        return;
    }
    o.background.clear();
    std::stringstream in(o.background_text);
    std::string item;
    while (std::getline(in, item, ',')) {
        char* end = nullptr;
        const float v = std::strtof(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v))
            throw Error("--background: '" + o.background_text + "' is neither sky nor three numbers R,G,B");
        o.background.push_back(v);
    }
}

void run_render(RenderOptions o) {
    parse_background(o);
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.threads);
    if (o.background.size() != 3) throw Error("--background needs three values R,G,B");
    if (o.run.empty() == o.ply.empty())
        throw Error("render: give either a training run folder (render RUN --light L) or --ply FILE");
    const RasterBackend backend = choose_backend(o.backend);
    if (!o.run.empty()) return run_relight(o, backend);
    if (o.scene.empty()) throw Error("render --ply needs --scene (the cameras to render from)");
    if (o.cameras_given) {
        // The one vocabulary (README): --cameras names the views for a PLY too; --split is its old spelling.
        const std::string& c = o.job.cameras;
        if (c != "all" && c != "train" && c != "test" && c != "validation")
            throw Error("--cameras '" + c +
                        "': render --ply renders the scene's views: all, train, test or "
                        "validation (orbits and camera JSON files are for runs)");
        o.split = c;
    }
    DatasetOptions dopt;
    dopt.downscale = o.downscale > 0 ? o.downscale : 1;
    const Dataset scene = load_dataset(o.scene, dopt);
    ViewDependentSurfels model = load_2dgs_ply(o.ply);
    std::printf("render: %zu surfels (SH degree %d) from %s, %zu views of %s\n", model.size(),
                model.sh_degree, o.ply.c_str(), scene.views.size(), o.scene.c_str());
    RasterSettings<float> settings;
    settings.background = o.background;
    int done = 0;
    // Reused: its buffers and the images' keep their memory from view to view.
    const std::unique_ptr<Rasterizer> rasterizer = make_rasterizer(backend);
    RasterImages<float> img;
    if (backend != RasterBackend::Cpu) std::printf("render: on %s\n", backend_description(backend).c_str());
    for (const View& v : scene.views) {
        if (o.split != "all" && o.split != split_name(v.split)) continue;
        const auto t0 = std::chrono::steady_clock::now();
        colors_for_view(model, v.camera.center());
        rasterizer->forward(v.camera, model.surfels, settings, img);
        const auto path = output_path(o.out, v.name, ".png");
        std::filesystem::create_directories(path.parent_path());
        write_png(path.string(), raster_channels(img, 0, 3));
        if (o.extra_maps) write_extra_maps(o, v, img);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::printf("  [%d] %s  %dx%d  %zu intersections  %.1f ms\n", ++done, path.string().c_str(),
                    v.camera.width, v.camera.height, rasterizer->intersections(), ms);
    }
    if (done == 0) throw Error("no view of " + o.scene + " is in split '" + o.split + "'");
    std::printf("render: wrote %d images to %s\n", done, o.out.c_str());
}

}  // namespace

void register_render(CLI::App& app) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Relight a trained run (render RUN --light L ...) or render a surfel PLY in the 2DGS layout "
        "(render --ply FILE --scene DIR)");
    cmd->add_option("run", o->run,
                    "training run folder (model.ply, lighting.lgmlp, appearance.json), or a bare relightable "
                    "PLY in the official LumiGauss layout (then --light must be an SH file or a panorama)");
    cmd->add_option("--ply", o->ply, "surfel model in the 2DGS PLY layout (instead of a run)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--scene", o->scene,
                    "scene folder (COLMAP or NeRF-OSR layout): its cameras; needed for --ply, and for a run "
                    "with --cameras train|test|validation|all|orbit unless the run recorded its scene "
                    "(RUN/scene.json; a scene whose photos of the same names have other cameras is refused)");
    cmd->add_option("-o,--output", o->out, "output folder")->capture_default_str();
    cmd->add_option("-r,--resolution,--downscale", o->downscale,
                    "downscale images by 1, 2, 4 or 8 (default: 1 for --ply, the run's training "
                    "resolution for a run; a camera JSON is used as is unless given)")
        ->check(CLI::IsMember({1, 2, 4, 8}));
    cmd->add_option("--split", o->split, "--ply: which views (the old spelling of --cameras for a PLY)")
        ->check(CLI::IsMember({"all", "train", "test", "validation"}))
        ->capture_default_str();
    cmd->add_option("--background", o->background_text,
                    "sky (a run: the light's own sky behind the surfels, a panorama as it is) or a colour "
                    "R,G,B in [0,1] (composited under colour and albedo using alpha); default black");
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)");
    cmd->add_option("--backend", o->backend,
                    "rasterize on the CPU or on the GPU (cuda: builds with the CUDA backend, on a machine "
                    "with a GPU; auto: the GPU when there is one)")
        ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
        ->capture_default_str();
    cmd->add_flag("--maps", o->extra_maps,
                  "--ply: also write alpha (PNG), expected depth (EXR) and world normals (PNG)");

    RelightJob& j = o->job;
    const std::string run_group = "Relighting a run";
    cmd->add_option("--light", j.light,
                    "the lighting: a training photo's name (its learned light), a .txt SH file (9 rows R G "
                    "B, world frame) or an equirectangular panorama (.hdr, .exr, .png, .jpg; top row = up); "
                    "prefixes photo:, sh:, pano: force the kind")
        ->group(run_group);
    cmd->add_option("--cameras", j.cameras,
                    "train, test, validation, all (the scene's views), orbit (a turntable around the "
                    "scene's SfM centre at its cameras' mean height and distance, intrinsics of its first "
                    "view), or a camera JSON file; --ply: all (default), train, test or validation")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_option("--view", j.views, "render only this camera (image name or its stem; repeatable)")
        ->allow_extra_args(false)
        ->group(run_group);
    cmd->add_option("--frames", j.orbit_frames, "cameras of --cameras orbit")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_option(
           "--up", j.up,
           "world up for --rotate/--spin, panoramas and orbits: auto (the up of the scene's or the "
           "JSON's cameras, not rounded to an axis), +z (synthetic scenes, Blender), -y (COLMAP y-down), "
           "+y, +x, -x, -z, or a vector X,Y,Z")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_option("--rotate", j.rotate_degrees,
                    "turn the environment by DEG about the up axis (right-handed: counter-clockwise seen "
                    "from above)")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_option("--spin", j.spin,
                    "render N frames per camera turning the environment by k*360/N (after --rotate)")
        ->group(run_group);
    cmd->add_option("--exposure", j.exposure, "multiply the light SH by E")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_flag("--match-exposure", j.match_exposure,
                  "first scale the light to the median brightness (DC luma) of the run's learned lights")
        ->group(run_group);
    cmd->add_option("--hdr-threshold", j.hdr_threshold,
                    "fake HDR for LDR panoramas: channel values above T (of 1) ...")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_option("--hdr-scale", j.hdr_scale,
                    "... are multiplied by S (1: off; the official NeRF-OSR settings use 10 to 30)")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_option("--outputs", o->outputs,
                    "all, or a comma list of shadowed, unshadowed, albedo, normal, shadow, irradiance, "
                    "depth, alpha")
        ->capture_default_str()
        ->group(run_group);
    cmd->add_flag("--exr", j.outputs.exr, "also write unclamped EXRs of the colour, shadow and normal maps")
        ->group(run_group);
    cmd->add_flag("--no-video", o->no_video, "no MP4 even if ffmpeg is installed")->group(run_group);
    cmd->add_option("--fps", j.fps, "frames per second of the MP4s")->capture_default_str()->group(run_group);
    cmd->add_flag("-q,--quiet", o->quiet, "print only the final line")->group(run_group);
    cmd->footer(
        "A run writes per camera (STEM = image name without extension; STEM_spinKKK with --spin; orbit_KKK "
        "for an orbit): STEM_shadowed.png, STEM_unshadowed.png, STEM_albedo.png, STEM_normal.png (world, "
        "(n+1)/2), STEM_shadow.png (1 - luma(unshadowed - shadowed intensity), 1 = lit), "
        "STEM_irradiance.png and STEM_irradiance_unshadowed.png (post-gamma intensity, divided by their max "
        "if > 1), STEM_irradiance.exr, STEM_depth.exr, STEM_alpha.png; with ffmpeg on the PATH and a spin or "
        "orbit, STEM_shadowed.mp4 / orbit_shadowed.mp4.");
    cmd->callback([o, cmd] {
        RenderOptions opts = *o;
        opts.background_given = cmd->count("--background") > 0;
        opts.split_given = cmd->count("--split") > 0;
        opts.cameras_given = cmd->count("--cameras") > 0;
        run_render(opts);
    });
}

}  // namespace lumigauss::cli
