// `lumigauss eval RUN --scene SCENE --protocol P -o REPORT [-r N]`: evaluates a training run folder on
// the test photos of a scene and writes REPORT/metrics.json, REPORT/report.md and REPORT/sheets/*.png
// (eval/report.h). Protocols: gt-env (eval/gt_env.h), for scenes that ship their true lighting; sol-nerf
// (eval/sol_nerf.h), the paper's NeRF-OSR protocol with per-scene constants from a config file; holdout
// (eval/holdout.h), for collections without ground-truth lighting: light fitted on the left half of each
// photo, scored on the right half.
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "commands.h"
#include "lumigauss/eval/gt_env.h"
#include "lumigauss/eval/holdout_report.h"
#include "lumigauss/eval/report.h"
#include "lumigauss/eval/sol_nerf.h"
#include "lumigauss/eval/sol_nerf_report.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/text.h"

namespace lumigauss::cli {
namespace {

struct EvalOptions {
    std::string run, scene, protocol = "gt-env", out = "eval", views = "test", backend = "cpu";
    int downscale = 0;  // 0: the run's config.json downscale (1 if unknown)
    int threads = 0;
    bool no_sheets = false, quiet = false;
    // sol-nerf
    std::string sol_config, sol_scene, env_root, mask_root;
    int angles = 0;  // 0: the config's
    // holdout
    std::string via = "auto";
    int fit_iterations = 300;
};

// -r when given, else the run's training resolution (1 when the run does not record it).
DatasetOptions evaluated_resolution(const EvalOptions& o, int run_downscale) {
    DatasetOptions dopt;
    dopt.downscale = o.downscale > 0 ? o.downscale : (run_downscale > 0 ? run_downscale : 1);
    return dopt;
}

// The mean over the channels of a surface's gain to the photos (eval-summary's up_gain, other_gain).
double mean_gain(const SurfaceRegion& r) {
    return (r.gain(0) + r.gain(1) + r.gain(2)) / 3.0;
}

void run_gt_env(const EvalOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    // Check the scene's ground truth before the (slower) model load, so a wrong scene fails at once.
    const GtSceneMeta meta = load_gt_scene_meta(o.scene);
    const RelightableRun run = load_relightable_run(o.run);
    const DatasetOptions dopt = evaluated_resolution(o, run.downscale);
    const Dataset scene = load_scene_of_run(o.run, o.scene, dopt);
    if (!o.quiet)
        std::printf("eval: %zu surfels, %zu training photos from %s; %zu %s views of %s at 1/%d\n",
                    run.model.size(), run.image_names.size(), o.run.c_str(),
                    scene.split(o.views == "train" ? Split::Train : Split::Test).size(), o.views.c_str(),
                    o.scene.c_str(), dopt.downscale);
    GtEnvOptions gopt;
    gopt.views = o.views == "train" ? Split::Train : Split::Test;
    gopt.keep_panels = !o.no_sheets;
    gopt.backend = choose_backend(o.backend);
    const GtEnvResult result = evaluate_gt_env(run, scene, meta, gopt);
    write_gt_env_report(o.out, result, {o.run, o.scene}, !o.no_sheets);
    const double s = seconds_since(t0);
    if (!o.quiet) {
        if (run.image_names.empty())
            std::printf("  light scale k = 1 (a bare PLY: no learned lights to fit it on)\n");
        else
            std::printf(
                "  light scale k = %.6g (fit on %zu training photos, relative residual %.3f); learned "
                "lights %.2f x as directional as the true ones, %.0f deg off (medians)\n",
                result.light.scale, result.light.per_photo.size(), result.light.relative_residual,
                result.light.median_direction_strength, result.light.median_direction_error_deg);
        if (const auto& ref = result.light_reference)
            std::printf(
                "  what the photos tell of their lights: %d of 9 directions seen (median), %.0f %% of the "
                "true lights unseen; seen-part residual %.3f (learned) / %.3f (reference with the true "
                "albedo and normals, whole light %.3f)\n",
                ref->median_seen, 100 * ref->unseen_share, ref->learned_seen_residual,
                ref->reference_seen_residual, ref->reference_residual);
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
        if (result.has_normal) {
            const SurfaceRegion &up = result.surfaces.up, &other = result.surfaces.other;
            std::printf(
                "  by surface: facing up %.2f dB (gain to the photos %.3f %.3f %.3f), the rest %.2f dB "
                "(gain %.3f %.3f %.3f)\n",
                up.psnr(), up.gain(0), up.gain(1), up.gain(2), other.psnr(), other.gain(0), other.gain(1),
                other.gain(2));
        }
        if (result.has_sky)
            std::printf(
                "  sky pixels (gt/mask = 0) with alpha > 0.5: %.2f %%; mean alpha over the sky %.4f\n",
                100 * result.sky_alpha_fraction, result.sky_mean_alpha);
        std::printf(
            "  evaluated pixels left empty (alpha <= 0.5): %.2f %%; shadowed PSNR over the others %.2f\n",
            100 * result.empty_fraction, result.mean_covered_shadowed_psnr);
        if (result.image_scaled)
            std::printf(
                "  light scale per channel fitted on the training images: k = %.4g %.4g %.4g; "
                "shadowed PSNR under it %.2f SSIM %.4f\n",
                result.image_light_scale[0], result.image_light_scale[1], result.image_light_scale[2],
                result.mean_image_scaled_shadowed.psnr, result.mean_image_scaled_shadowed.ssim);
    }
    // One key=value line for scripts (bench/plaza.sh); "nan" where the scene has no such ground truth.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::printf(
        "eval-summary: shadowed_psnr=%.4f shadowed_ssim=%.4f unshadowed_psnr=%.4f unshadowed_ssim=%.4f "
        "albedo_psnr=%.4f normal_mean_deg=%.3f normal_median_deg=%.3f render_ms=%.2f sky_alpha=%.4f "
        "light_residual=%.4f empty=%.4f covered_psnr=%.4f scaled_psnr=%.4f sky_mean_alpha=%.4f "
        "light_direction=%.4f light_direction_error_deg=%.2f up_psnr=%.4f other_psnr=%.4f up_gain=%.4f "
        "other_gain=%.4f light_seen_residual=%.4f light_reference_residual=%.4f "
        "light_reference_seen_residual=%.4f\n",
        result.mean_shadowed.psnr, result.mean_shadowed.ssim, result.mean_unshadowed.psnr,
        result.mean_unshadowed.ssim, result.has_albedo ? result.mean_albedo.psnr : nan,
        result.has_normal ? result.mean_normal.mean_deg : nan,
        result.has_normal ? result.mean_normal.median_deg : nan, result.median_render_ms,
        result.has_sky ? result.sky_alpha_fraction : nan, result.light.relative_residual,
        result.empty_fraction, result.mean_covered_shadowed_psnr,
        result.image_scaled ? result.mean_image_scaled_shadowed.psnr : nan,
        result.has_sky ? result.sky_mean_alpha : nan, result.light.median_direction_strength,
        result.light.median_direction_error_deg, result.has_normal ? result.surfaces.up.psnr() : nan,
        result.has_normal ? result.surfaces.other.psnr() : nan,
        result.has_normal ? mean_gain(result.surfaces.up) : nan,
        result.has_normal ? mean_gain(result.surfaces.other) : nan,
        result.light_reference ? result.light_reference->learned_seen_residual : nan,
        result.light_reference ? result.light_reference->reference_residual : nan,
        result.light_reference ? result.light_reference->reference_seen_residual : nan);
    std::printf("eval: wrote %s/metrics.json and %s/report.md (%.1f s)\n", o.out.c_str(), o.out.c_str(), s);
}

// Where a shipped configs/sol_nerf/NAME.json may be: beside the working folder, or up from the binary (build
// trees put it in build/ or build/apps/, installs in bin/ next to share/).
std::vector<std::string> shipped_config_dirs() {
    namespace fs = std::filesystem;
    std::vector<std::string> dirs{"configs/sol_nerf"};
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec)
        for (const char* up : {"..", "../..", "../share/lumigauss"})
            dirs.push_back((exe.parent_path() / up / "configs" / "sol_nerf").lexically_normal().string());
    return dirs;
}

// --sol-config, else the shipped config of --sol-scene or of the scene the path names.
std::string sol_config_path(const EvalOptions& o) {
    if (!o.sol_config.empty()) return o.sol_config;
    const std::string name = o.sol_scene.empty() ? guess_sol_nerf_scene(o.scene) : o.sol_scene;
    if (name.empty())
        throw Error(
            "--protocol sol-nerf: give --sol-config FILE, or --sol-scene lk2|st|lwp for a shipped "
            "config (the scene path " +
            o.scene + " names none of them)");
    const std::vector<std::string> dirs = shipped_config_dirs();
    if (auto found = find_shipped_sol_nerf_config(name, dirs)) return *found;
    const std::string file = name + ".json";
    throw Error("--protocol sol-nerf: no shipped " + file + " in " + dirs.front() +
                " or up from the binary; give --sol-config configs/sol_nerf/" + file);
}

void print_sol_nerf(const SolNerfResult& result) {
    for (const SolNerfImageResult& im : result.images)
        std::printf(
            "  %-28s angle %7.2f deg%s  shadowed PSNR %6.2f SSIM %.4f | unshadowed PSNR %6.2f SSIM "
            "%.4f\n",
            im.config.name.c_str(), im.best_angle * 180.0 / std::numbers::pi,
            im.best_at_range_edge() ? " (range end)" : "", im.shadowed.psnr, im.shadowed.ssim,
            im.unshadowed.psnr, im.unshadowed.ssim);
    std::printf("  mean: shadowed PSNR %.2f SSIM %.4f MSE %.5f MAE %.4f | unshadowed PSNR %.2f SSIM %.4f\n",
                result.mean_shadowed.psnr, result.mean_shadowed.ssim, result.mean_shadowed.mse,
                result.mean_shadowed.mae, result.mean_unshadowed.psnr, result.mean_unshadowed.ssim);
}

void run_sol_nerf(const EvalOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    // Check the config before the (slower) model load, so a wrong config fails at once.
    const SolNerfConfig config = load_sol_nerf_config(sol_config_path(o));
    const TrainedRun run = load_run_or_ply(o.run);
    const DatasetOptions dopt = evaluated_resolution(o, run.downscale);
    const Dataset scene = load_scene_of_run(o.run, o.scene, dopt);
    if (!o.quiet)
        std::printf("eval: %zu surfels from %s; %zu test images of %s at 1/%d, config %s, %d angles each\n",
                    run.model.size(), o.run.c_str(), config.images.size(), o.scene.c_str(), dopt.downscale,
                    config.path.c_str(), o.angles > 0 ? o.angles : config.angles);
    SolNerfOptions sopt;
    sopt.keep_panels = !o.no_sheets;
    sopt.backend = choose_backend(o.backend);
    sopt.angles = o.angles;
    sopt.roots = {o.scene, o.env_root, o.mask_root};
    sopt.sides = run.side_rule;
    const SolNerfResult result = evaluate_sol_nerf(run.model, scene, config, sopt);
    write_sol_nerf_report(o.out, result, {o.run, o.scene}, !o.no_sheets);
    if (!o.quiet) print_sol_nerf(result);
    // The gt-env summary keys (albedo and normals: nan, NeRF-OSR has no such ground truth), then MSE/MAE.
    std::printf(
        "eval-summary: shadowed_psnr=%.4f shadowed_ssim=%.4f unshadowed_psnr=%.4f unshadowed_ssim=%.4f "
        "albedo_psnr=nan normal_mean_deg=nan normal_median_deg=nan render_ms=%.2f shadowed_mse=%.6f "
        "shadowed_mae=%.6f unshadowed_mse=%.6f unshadowed_mae=%.6f search_s=%.2f\n",
        result.mean_shadowed.psnr, result.mean_shadowed.ssim, result.mean_unshadowed.psnr,
        result.mean_unshadowed.ssim, result.median_render_ms, result.mean_shadowed.mse,
        result.mean_shadowed.mae, result.mean_unshadowed.mse, result.mean_unshadowed.mae,
        result.search_seconds);
    std::printf("eval: wrote %s/metrics.json and %s/report.md (%.1f s)\n", o.out.c_str(), o.out.c_str(),
                seconds_since(t0));
}

void run_holdout(const EvalOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    const TrainedRun run = load_run_or_ply(o.run);
    const DatasetOptions dopt = evaluated_resolution(o, run.downscale);
    const Dataset scene = load_scene_of_run(o.run, o.scene, dopt);
    HoldoutOptions hopt;
    hopt.views = o.views == "train" ? Split::Train : Split::Test;
    hopt.keep_panels = !o.no_sheets;
    hopt.backend = choose_backend(o.backend);
    const bool has_network = run.lighting.num_images() > 0;
    hopt.fit.variable =
        o.via == "sh" || (o.via == "auto" && !has_network) ? LightVariable::Sh : LightVariable::Embedding;
    hopt.fit.iterations = o.fit_iterations;
    if (!o.quiet)
        std::printf(
            "eval: %zu surfels from %s; %zu %s views of %s at 1/%d; light fitted on the left half "
            "via the %s (%d iterations), scored on the right half\n",
            run.model.size(), o.run.c_str(), scene.split(hopt.views).size(), o.views.c_str(), o.scene.c_str(),
            dopt.downscale, light_variable_name(hopt.fit.variable), hopt.fit.iterations);
    if (!o.quiet)
        hopt.on_image = [&](const HoldoutImageResult& im, std::size_t done, std::size_t total) {
            std::printf(
                "  [%zu/%zu %.0f s] %-28s fit PSNR %6.2f/%6.2f | shadowed PSNR %6.2f SSIM %.4f | unshadowed "
                "PSNR %6.2f SSIM %.4f\n",
                done, total, seconds_since(t0), im.name.c_str(), im.fit_psnr, im.fit_psnr_unshadowed,
                im.shadowed.psnr, im.shadowed.ssim, im.unshadowed.psnr, im.unshadowed.ssim);
            std::fflush(stdout);
        };
    const HoldoutResult result = evaluate_holdout(run, scene, hopt);
    write_holdout_report(o.out, result, {o.run, o.scene}, dopt.downscale, !o.no_sheets);
    if (!o.quiet) {
        std::printf("  mean: shadowed PSNR %.2f SSIM %.4f | unshadowed PSNR %.2f SSIM %.4f (fit %.2f dB)\n",
                    result.mean_shadowed.psnr, result.mean_shadowed.ssim, result.mean_unshadowed.psnr,
                    result.mean_unshadowed.ssim, result.mean_fit_psnr);
    }
    std::printf(
        "eval-summary: shadowed_psnr=%.4f shadowed_ssim=%.4f unshadowed_psnr=%.4f unshadowed_ssim=%.4f "
        "albedo_psnr=nan normal_mean_deg=nan normal_median_deg=nan render_ms=%.2f fit_psnr=%.4f "
        "fit_ms=%.1f\n",
        result.mean_shadowed.psnr, result.mean_shadowed.ssim, result.mean_unshadowed.psnr,
        result.mean_unshadowed.ssim, result.median_render_ms, result.mean_fit_psnr, result.median_fit_ms);
    std::printf("eval: wrote %s/metrics.json and %s/report.md (%.1f s)\n", o.out.c_str(), o.out.c_str(),
                seconds_since(t0));
}

void run_eval(EvalOptions o) {
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.threads);
    o.scene = scene_for_run(o.run, o.scene, "eval needs the scene");
    if (o.protocol == "sol-nerf")
        run_sol_nerf(o);
    else if (o.protocol == "holdout")
        run_holdout(o);
    else
        run_gt_env(o);
}

}  // namespace

void register_eval(CLI::App& app) {
    auto o = std::make_shared<EvalOptions>();
    CLI::App* cmd = app.add_subcommand("eval", "Evaluate a training run on the test photos of a scene");
    cmd->add_option("run", o->run,
                    "training run folder (model.ply, lighting.lgmlp, appearance.json); sol-nerf also takes a "
                    "bare relightable PLY (the official LumiGauss layout)")
        ->required();
    cmd->add_option(
        "--scene", o->scene,
        "the scene: for gt-env with ground truth (meta.json, env/COND_sh.txt, gt/); for sol-nerf a "
        "NeRF-OSR scene (COLMAP layout as on Zenodo, or NeRF-OSR's final/ layout). Default: the scene "
        "the run was trained on (RUN/scene.json); a scene whose photos of the same names have other "
        "cameras is refused");
    cmd->add_option("--protocol", o->protocol,
                    "gt-env: render each test photo under its true environment SH, scaled by the one "
                    "light scale fitted on the training photos; sol-nerf: the paper's NeRF-OSR protocol "
                    "(ground-truth panorama -> fake HDR -> SH -> fixed rotation -> best of N y-angles by "
                    "shadowed masked PSNR on the photo); holdout: for photos without ground-truth lighting, "
                    "fit each photo's light on its left half (fit-light) and score its right half")
        ->check(CLI::IsMember({"gt-env", "sol-nerf", "holdout"}))
        ->capture_default_str();
    cmd->add_option("-o,--output", o->out, "report folder")->capture_default_str();
    cmd->add_option("-r,--resolution,--downscale", o->downscale,
                    "evaluate at 1/1, 1/2, 1/4 or 1/8 resolution (default: the run's training resolution)")
        ->check(CLI::IsMember({0, 1, 2, 4, 8}));
    cmd->add_option("--cameras,--views", o->views,
                    "which photos, gt-env and holdout. test: the protocol (novel views, novel lights); "
                    "train: diagnostic, the "
                    "training views (gt-env: under their own true lights; separates lighting from novel-view "
                    "geometry)")
        ->check(CLI::IsMember({"test", "train"}))
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)");
    cmd->add_option("--backend", o->backend,
                    "rasterize the scored renders on the CPU or on the GPU (cuda: builds with the CUDA "
                    "backend, on a machine with a GPU; auto: the GPU when there is one)")
        ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
        ->capture_default_str();
    cmd->add_flag("--no-sheets", o->no_sheets, "skip the contact sheets");
    cmd->add_flag("-q,--quiet", o->quiet, "print only the final line");
    const std::string sol = "sol-nerf";
    cmd->add_option("--sol-config", o->sol_config,
                    "the per-scene constants (test images, env maps, masks, rotations, HDR boost, y-ranges), "
                    "JSON as configs/sol_nerf/README.md; default: the shipped config of --sol-scene")
        ->group(sol);
    cmd->add_option("--sol-scene", o->sol_scene,
                    "use the shipped configs/sol_nerf/NAME.json (default: lk2, st or lwp when the scene path "
                    "names one, e.g. data/lk2_colmap/undistorted)")
        ->check(CLI::IsMember({"lk2", "st", "lwp"}))
        ->group(sol);
    cmd->add_option("--env-root", o->env_root,
                    "folder the config's relative env_map paths start from, i.e. the one holding ENV_MAP_CC/ "
                    "(default: the scene folder, then its final/)")
        ->group(sol);
    cmd->add_option("--mask-root", o->mask_root,
                    "folder the config's relative mask paths start from (the NeRF-OSR evaluation masks; "
                    "default: the scene folder, then its final/)")
        ->group(sol);
    cmd->add_option("--angles", o->angles, "y-angles searched per image (default: the config's, 51)")
        ->check(CLI::PositiveNumber)
        ->group(sol);
    const std::string holdout = "holdout";
    cmd->add_option("--via", o->via,
                    "what fit-light optimises: sh, embedding (through the run's lighting network), auto "
                    "(embedding when the run has a network)")
        ->check(CLI::IsMember({"auto", "sh", "embedding"}))
        ->capture_default_str()
        ->group(holdout);
    cmd->add_option("--fit-iterations", o->fit_iterations, "Adam iterations of each fit")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str()
        ->group(holdout);
    cmd->callback([o] { run_eval(*o); });
}

}  // namespace lumigauss::cli
