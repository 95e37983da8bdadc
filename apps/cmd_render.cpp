// `lumigauss render --ply FILE --scene DIR`: renders a surfel PLY in the 2DGS layout from the cameras of a
// scene, one PNG per view named after its image, so the rasterizer can be checked from outside and 2DGS
// models trained elsewhere can be rendered.
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/scene/splat_ply.h"
#include "lumigauss/util/error.h"

namespace lumigauss::cli {
namespace {

struct RenderOptions {
    std::string ply, scene, out = "renders", split = "all";
    int downscale = 1;
    int threads = 0;
    std::vector<float> background{0, 0, 0};
    bool extra_maps = false;
};

std::filesystem::path output_path(const std::string& dir, const std::string& image_name,
                                  const std::string& suffix) {
    std::filesystem::path p = std::filesystem::path(dir) / image_name;
    p.replace_extension();
    p += suffix;
    return p;
}

Image color_image(const RasterImages<float>& img) {
    Image out(img.width, img.height, 3);
    for (std::size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = img.color[i];
    return out;
}

void write_extra_maps(const RenderOptions& o, const View& v, const RasterImages<float>& img) {
    Image alpha(img.width, img.height, 1), depth(img.width, img.height, 1), normal(img.width, img.height, 3);
    for (std::size_t p = 0; p < img.alpha.size(); ++p) {
        const float a = img.alpha[p];
        alpha.pixels[p] = a;
        depth.pixels[p] = a > 1e-6f ? img.depth[p] / a : 0.0f;
        Vec3f n{img.normal[3 * p], img.normal[3 * p + 1], img.normal[3 * p + 2]};
        const float len = length(n);
        if (len > 0) n = n / len;
        for (int k = 0; k < 3; ++k) normal.pixels[3 * p + k] = len > 0 ? 0.5f * (n[k] + 1) : 0.5f;
    }
    write_png(output_path(o.out, v.name, "_alpha.png").string(), alpha);
    write_exr(output_path(o.out, v.name, "_depth.exr").string(), depth);
    write_png(output_path(o.out, v.name, "_normal.png").string(), normal);
}

void run_render(const RenderOptions& o) {
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.threads);
    if (o.background.size() != 3) throw Error("--background needs three values R,G,B");
    DatasetOptions dopt;
    dopt.downscale = o.downscale;
    const Dataset scene = load_dataset(o.scene, dopt);
    ViewDependentSurfels model = load_2dgs_ply(o.ply);
    std::printf("render: %zu surfels (SH degree %d) from %s, %zu views of %s\n", model.size(),
                model.sh_degree, o.ply.c_str(), scene.views.size(), o.scene.c_str());
    RasterSettings<float> settings;
    settings.background = o.background;
    int done = 0;
    RasterState<float> state;  // reused: its buffers and the images' keep their memory from view to view
    RasterImages<float> img;
    for (const View& v : scene.views) {
        if (o.split != "all" && o.split != split_name(v.split)) continue;
        const auto t0 = std::chrono::steady_clock::now();
        colors_for_view(model, v.camera.center());
        rasterize_forward_cpu(v.camera, model.surfels, settings, state, img);
        const auto path = output_path(o.out, v.name, ".png");
        std::filesystem::create_directories(path.parent_path());
        write_png(path.string(), color_image(img));
        if (o.extra_maps) write_extra_maps(o, v, img);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::printf("  [%d] %s  %dx%d  %zu intersections  %.1f ms\n", ++done, path.string().c_str(),
                    v.camera.width, v.camera.height, state.intersections(), ms);
    }
    if (done == 0) throw Error("no view of " + o.scene + " is in split '" + o.split + "'");
    std::printf("render: wrote %d images to %s\n", done, o.out.c_str());
}

}  // namespace

void register_render(CLI::App& app) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd =
        app.add_subcommand("render", "Render a surfel PLY (2DGS layout) from the cameras of a scene");
    cmd->add_option("--ply", o->ply, "surfel model in the 2DGS PLY layout")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--scene", o->scene, "scene folder (COLMAP or NeRF-OSR layout)")->required();
    cmd->add_option("-o,--output", o->out, "output folder")->capture_default_str();
    cmd->add_option("-r,--downscale", o->downscale, "downscale images by 1, 2, 4 or 8")
        ->check(CLI::IsMember({1, 2, 4, 8}))
        ->capture_default_str();
    cmd->add_option("--split", o->split, "which views: all, train, test")
        ->check(CLI::IsMember({"all", "train", "test", "validation"}))
        ->capture_default_str();
    cmd->add_option("--background", o->background, "background colour R,G,B in [0,1]")->delimiter(',');
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)");
    cmd->add_flag("--maps", o->extra_maps,
                  "also write alpha (PNG), expected depth (EXR) and world normals (PNG)");
    cmd->callback([o] { run_render(*o); });
}

}  // namespace lumigauss::cli
