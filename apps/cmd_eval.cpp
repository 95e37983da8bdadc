// `lumigauss eval RUN --scene SCENE --protocol gt-env -o REPORT [-r N]`: evaluates a training run folder on
// the test photos of a scene and writes REPORT/metrics.json, REPORT/report.md and REPORT/sheets/*.png
// (eval/report.h). Protocols: gt-env (eval/gt_env.h), for scenes that ship their true lighting.
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "commands.h"
#include "lumigauss/eval/gt_env.h"
#include "lumigauss/eval/report.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/util/error.h"

namespace lumigauss::cli {
namespace {

struct EvalOptions {
    std::string run, scene, protocol = "gt-env", out = "eval", views = "test";
    int downscale = 0;  // 0: the run's config.json downscale (1 if unknown)
    int threads = 0;
    bool no_sheets = false, quiet = false;
};

void run_eval(const EvalOptions& o) {
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.threads);
    const auto t0 = std::chrono::steady_clock::now();
    // Check the scene's ground truth before the (slower) model load, so a wrong scene fails at once.
    const GtSceneMeta meta = load_gt_scene_meta(o.scene);
    const RelightableRun run = load_relightable_run(o.run);
    DatasetOptions dopt;
    dopt.downscale = o.downscale > 0 ? o.downscale : (run.downscale > 0 ? run.downscale : 1);
    const Dataset scene = load_dataset(o.scene, dopt);
    if (!o.quiet)
        std::printf("eval: %zu surfels, %zu training photos from %s; %zu %s views of %s at 1/%d\n",
                    run.model.size(), run.image_names.size(), o.run.c_str(),
                    scene.split(o.views == "train" ? Split::Train : Split::Test).size(), o.views.c_str(),
                    o.scene.c_str(), dopt.downscale);
    GtEnvOptions gopt;
    gopt.views = o.views == "train" ? Split::Train : Split::Test;
    gopt.keep_panels = !o.no_sheets;
    const GtEnvResult result = evaluate_gt_env(run, scene, meta, gopt);
    write_gt_env_report(o.out, result, {o.run, o.scene}, !o.no_sheets);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!o.quiet) {
        std::printf("  light scale k = %.6g (fit on %zu training photos, relative residual %.3f)\n",
                    result.light.scale, result.light.per_photo.size(), result.light.relative_residual);
        for (const GtEnvImageResult& im : result.images)
            std::printf("  %-24s %-14s shadowed PSNR %6.2f SSIM %.4f | unshadowed PSNR %6.2f SSIM %.4f\n",
                        im.name.c_str(), im.condition.c_str(), im.shadowed.psnr, im.shadowed.ssim,
                        im.unshadowed.psnr, im.unshadowed.ssim);
        std::printf("  mean: shadowed PSNR %.2f SSIM %.4f | unshadowed PSNR %.2f SSIM %.4f\n",
                    result.mean_shadowed.psnr, result.mean_shadowed.ssim, result.mean_unshadowed.psnr,
                    result.mean_unshadowed.ssim);
        if (result.has_albedo)
            std::printf("  albedo PSNR %.2f (linear), %.2f (gamma)\n", result.mean_albedo.psnr,
                        result.mean_albedo_gamma.psnr);
        if (result.has_normal)
            std::printf("  normals: mean %.2f deg, median %.2f deg\n", result.mean_normal.mean_deg,
                        result.mean_normal.median_deg);
    }
    // One key=value line for scripts (bench/plaza.sh); "nan" where the scene has no such ground truth.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::printf(
        "eval-summary: shadowed_psnr=%.4f shadowed_ssim=%.4f unshadowed_psnr=%.4f unshadowed_ssim=%.4f "
        "albedo_psnr=%.4f normal_mean_deg=%.3f normal_median_deg=%.3f render_ms=%.2f\n",
        result.mean_shadowed.psnr, result.mean_shadowed.ssim, result.mean_unshadowed.psnr,
        result.mean_unshadowed.ssim, result.has_albedo ? result.mean_albedo.psnr : nan,
        result.has_normal ? result.mean_normal.mean_deg : nan,
        result.has_normal ? result.mean_normal.median_deg : nan, result.median_render_ms);
    std::printf("eval: wrote %s/metrics.json and %s/report.md (%.1f s)\n", o.out.c_str(), o.out.c_str(), s);
}

}  // namespace

void register_eval(CLI::App& app) {
    auto o = std::make_shared<EvalOptions>();
    CLI::App* cmd = app.add_subcommand("eval", "Evaluate a training run on the test photos of a scene");
    cmd->add_option("run", o->run, "training run folder (model.ply, lighting.lgmlp, appearance.json)")
        ->required();
    cmd->add_option("--scene", o->scene, "scene folder with ground truth (meta.json, env/COND_sh.txt, gt/)")
        ->required();
    cmd->add_option("--protocol", o->protocol,
                    "gt-env: render each test photo under its true environment SH, scaled by the one "
                    "light scale fitted on the training photos")
        ->check(CLI::IsMember({"gt-env"}))
        ->capture_default_str();
    cmd->add_option("-o,--output", o->out, "report folder")->capture_default_str();
    cmd->add_option("-r,--downscale", o->downscale,
                    "evaluate at 1/1, 1/2, 1/4 or 1/8 resolution (default: the run's training resolution)")
        ->check(CLI::IsMember({0, 1, 2, 4, 8}));
    cmd->add_option("--views", o->views,
                    "test: the protocol (novel views, novel lights); train: diagnostic, the training views "
                    "under their own true lights (separates lighting from novel-view geometry)")
        ->check(CLI::IsMember({"test", "train"}))
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)");
    cmd->add_flag("--no-sheets", o->no_sheets, "skip the contact sheets");
    cmd->add_flag("-q,--quiet", o->quiet, "print only the final line");
    cmd->callback([o] { run_eval(*o); });
}

}  // namespace lumigauss::cli
