// `lumigauss synth -o DIR [--preset tiny|demo|bench] [--landmark plaza|temple] ...`: render a procedural
// landmark into a dataset in the form users bring (COLMAP + images + masks) plus ground truth in
// data/plaza's layout. A preset sets every default; explicit flags override it.
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "lumigauss/synth/synth.h"

namespace lumigauss::cli {

namespace {

struct SynthFlags {
    std::string output, preset = "demo", scene = "plaza";
    int width = 0, height = 0, train = 0, test = 0, spp_side = 0, points = 0, gt_surfels = 0;
    unsigned long long seed = 1;
    double transients = 0;
    bool force = false, verbose = false, quiet = false, object_masks = false;
    CLI::Option *o_width, *o_height, *o_train, *o_test, *o_transients, *o_spp, *o_points, *o_gt_surfels;
};

synth::SynthOptions to_options(const SynthFlags& f) {
    synth::SynthOptions o = synth::synth_preset(f.preset);
    o.output_dir = f.output;
    o.scene = f.scene;
    o.seed = f.seed;
    if (f.o_width->count()) o.width = f.width;
    if (f.o_height->count()) o.height = f.height;
    if (f.o_train->count()) o.n_train = f.train;
    if (f.o_test->count()) o.n_test = f.test;
    if (f.o_transients->count()) o.transient_fraction = f.transients;
    if (f.o_spp->count()) o.samples_per_side = f.spp_side;
    if (f.o_points->count()) o.point_candidates = f.points;
    if (f.o_gt_surfels->count()) o.gt_surfels = f.gt_surfels;
    o.object_masks = f.object_masks;
    o.overwrite = f.force;
    o.verbose = f.verbose;
    return o;
}

void run_synth(const SynthFlags& f) {
    const synth::SynthOptions o = to_options(f);
    const synth::SynthSummary s = synth::generate_synthetic_scene(o);
    if (f.quiet) return;
    std::printf(
        "synth: wrote %s: landmark %s, %dx%d, %d train (%d with pedestrians) + %d test photos, %d lighting "
        "conditions, %d points3D, %d ground-truth surfels in %.2f s\n",
        o.output_dir.c_str(), o.scene.c_str(), o.width, o.height, s.n_train, s.n_with_transients, s.n_test,
        s.n_conditions, s.n_points, s.n_gt_surfels, s.seconds);
}

}  // namespace

void register_synth(CLI::App& app) {
    auto f = std::make_shared<SynthFlags>();
    CLI::App* cmd = app.add_subcommand(
        "synth",
        "Render a procedural landmark under many lightings into a dataset (COLMAP text model, sRGB photos, "
        "masks, split.csv) with ground truth (albedo, normals, masks, env SH) in data/plaza's layout");
    cmd->add_option("-o,--output", f->output, "Output folder (created; must be empty unless --force)")
        ->required();
    cmd->add_option("--preset", f->preset,
                    "tiny (64x48, 8+2 photos), demo (160x120, 40+6), bench (320x240, 60+12)")
        ->check(CLI::IsMember({"tiny", "demo", "bench"}))
        ->capture_default_str();
    cmd->add_option("--landmark,--scene", f->scene, "Landmark: plaza or temple (--scene: the old name)")
        ->check(CLI::IsMember({"plaza", "temple"}))
        ->capture_default_str();
    f->o_width = cmd->add_option("--width", f->width, "Image width in pixels")->check(CLI::Range(8, 8192));
    f->o_height =
        cmd->add_option("--height", f->height, "Image height in pixels")->check(CLI::Range(8, 8192));
    f->o_train =
        cmd->add_option("--train", f->train, "Number of training photos")->check(CLI::Range(2, 9999));
    f->o_test = cmd->add_option("--test", f->test, "Number of test photos (unseen views and lightings)")
                    ->check(CLI::Range(0, 9999));
    cmd->add_option("--seed", f->seed, "Random seed: the same seed gives byte-identical files")
        ->capture_default_str();
    f->o_transients =
        cmd->add_option("--transients", f->transients, "Fraction of training photos with pedestrians (0..1)")
            ->check(CLI::Range(0.0, 1.0));
    f->o_spp = cmd->add_option("--spp-side", f->spp_side, "Samples per pixel side (2: 2x2 stratified)")
                   ->check(CLI::Range(1, 16));
    f->o_points = cmd->add_option("--points", f->points, "Surface samples tried for points3D")
                      ->check(CLI::Range(0, 10000000));
    f->o_gt_surfels =
        cmd->add_option("--gt-surfels", f->gt_surfels,
                        "About how many ground-truth surfels to write to gt/surfels.ply (0: no file)")
            ->check(CLI::Range(0, 10000000));
    cmd->add_flag(
        "--object-masks", f->object_masks,
        "Write masks/ as foreground masks of the landmark (255 on it, 0 on the ground, people and sky), "
        "as collections of one object come (train with --set mask_mode=object)");
    cmd->add_flag("--force", f->force, "Replace the dataset files of an existing output folder");
    CLI::Option* verbose = cmd->add_flag("-v,--verbose", f->verbose, "Print each photo as it is rendered");
    cmd->add_flag("-q,--quiet", f->quiet, "Print nothing (errors still go to stderr)")->excludes(verbose);
    cmd->callback([f] { run_synth(*f); });
}

}  // namespace lumigauss::cli
