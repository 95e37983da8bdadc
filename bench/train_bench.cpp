// One training iteration, broken down by phase, for stage 1 (unshadowed) and stage 3 (shadowed + 0.001
// unshadowed in one 6-channel pass, physical losses), on a real scene with the surfel count raised to a
// target by jittered copies of the SfM points. Prints a table of per-phase medians in milliseconds.
//
// With --checkpoint, the surfels, lighting and optimizer state of a real run (e.g. a paper-preset run on
// plaza at iteration 6000) replace the synthetic surfel set: trained surfels are smaller, more opaque and lie
// in the surfaces, which changes the rasterizer's cost a lot.
//
// Usage: train_bench SCENE [--surfels N | --checkpoint RUN/checkpoint.lgck] [--iterations K] [--threads T]
//                          [--downscale R]
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "lumigauss/io/dataset.h"
#include "lumigauss/synth/rng.h"
#include "lumigauss/train/checkpoint.h"
#include "lumigauss/train/trainer.h"
#include "lumigauss/util/error.h"

namespace lg = lumigauss;

namespace {

struct Args {
    std::string scene, checkpoint;
    std::size_t surfels = 100000;
    int iterations = 20, threads = 0, downscale = 1;
};

Args parse(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string s = argv[i];
        auto next = [&]() -> const char* {
            if (i + 1 >= argc) throw lg::Error(s + " needs a value");
            return argv[++i];
        };
        if (s == "--surfels")
            a.surfels = std::size_t(std::atol(next()));
        else if (s == "--iterations")
            a.iterations = std::atoi(next());
        else if (s == "--threads")
            a.threads = std::atoi(next());
        else if (s == "--checkpoint")
            a.checkpoint = next();
        else if (s == "--downscale")
            a.downscale = std::atoi(next());
        else
            a.scene = s;
    }
    if (a.scene.empty())
        throw lg::Error("usage: train_bench SCENE [--surfels N] [--iterations K] [--threads T]");
    return a;
}

// The SfM points plus jittered copies (Gaussian, sigma = 0.5% of the point cloud's extent) up to n.
void grow_points(std::vector<lg::Vec3f>& xyz, std::vector<lg::Vec3f>& rgb, std::size_t n) {
    lg::Vec3f lo = xyz[0], hi = xyz[0];
    for (const auto& p : xyz)
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    const float sigma = 0.005f * lg::length(hi - lo);
    lg::synth::Rng rng(12345);
    const std::size_t base = xyz.size();
    for (std::size_t i = 0; xyz.size() < n; ++i) {
        const std::size_t k = i % base;
        xyz.push_back(xyz[k] +
                      lg::Vec3f{float(rng.normal()), float(rng.normal()), float(rng.normal())} * sigma);
        rgb.push_back(rgb[k]);
    }
    xyz.resize(n), rgb.resize(n);
}

using Times = lg::Trainer::PhaseTimes;
constexpr int kPhases = 8;
const char* kPhaseNames[kPhases] = {"shading",
                                    "rasterize forward",
                                    "image+geometry losses",
                                    "rasterize backward",
                                    "shading backward",
                                    "physical losses",
                                    "optimizer",
                                    "densify"};
double phase(const Times& t, int i) {
    const double v[kPhases] = {t.shading,          t.raster_forward, t.losses,    t.raster_backward,
                               t.shading_backward, t.physical,       t.optimizer, t.densify};
    return v[i];
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

// Per-phase medians (ms) and the median of the whole iteration, after two warm-up iterations.
std::vector<double> measure(lg::Trainer& trainer, int iterations) {
    std::vector<std::vector<double>> samples(kPhases + 1);
    for (int i = 0; i < iterations + 2; ++i) {
        const Times before = trainer.phase_times();
        trainer.step();
        const Times after = trainer.phase_times();
        if (i < 2) continue;
        double total = 0;
        for (int p = 0; p < kPhases; ++p) {
            const double ms = 1e3 * (phase(after, p) - phase(before, p));
            samples[std::size_t(p)].push_back(ms);
            total += ms;
        }
        samples[kPhases].push_back(total);
    }
    std::vector<double> out;
    for (auto& s : samples) out.push_back(median(s));
    return out;
}

}  // namespace

int main(int argc, char** argv) try {
    const Args args = parse(argc, argv);
    std::unique_ptr<tbb::global_control> limit;
    if (args.threads > 0)
        limit =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, args.threads);
    lg::DatasetOptions dopt;
    dopt.downscale = args.downscale;
    const lg::Dataset data = lg::load_dataset(args.scene, dopt);
    const auto views = lg::load_train_views(data);

    // Stage 1 and stage 3 copies of one setup, with densification off so the surfel count stays fixed.
    auto configure = [](lg::TrainConfig c, bool shadowed) {
        c.densify_until = 0;
        c.start_regularization = 0;  // normal + distortion losses on, as for most of a run
        c.iterations = 1000000;
        c.warmup = c.start_shadowed = shadowed ? 1 : 999999;  // shadowed: iteration 1 is stage 2, then 3
        return c;
    };
    std::unique_ptr<lg::Trainer> t1, t3;
    std::size_t surfels = args.surfels;
    if (!args.checkpoint.empty()) {
        lg::TrainState state = lg::load_checkpoint(args.checkpoint);
        surfels = state.model.size();
        const lg::TrainConfig saved = state.config;
        lg::TrainState copy = state;
        state.config = configure(saved, false);
        copy.config = configure(saved, true);
        state.iteration = copy.iteration = 0;
        t1 = std::make_unique<lg::Trainer>(views, std::move(state));
        t3 = std::make_unique<lg::Trainer>(views, std::move(copy));
    } else {
        std::vector<lg::Vec3f> xyz = data.point_xyz, rgb = data.point_rgb;
        grow_points(xyz, rgb, args.surfels);
        const lg::TrainConfig c = lg::train_preset("paper");
        t1 = std::make_unique<lg::Trainer>(views, xyz, rgb, configure(c, false));
        t3 = std::make_unique<lg::Trainer>(views, xyz, rgb, configure(c, true));
    }
    t3->step();  // the stage-2 iteration
    const auto m1 = measure(*t1, args.iterations);
    const auto m3 = measure(*t3, args.iterations);

    std::printf(
        "scene %s, %dx%d, %zu surfels (%s), %zu photos, median of %d iterations (ms)\n", args.scene.c_str(),
        views[0].camera.width, views[0].camera.height, surfels,
        args.checkpoint.empty() ? "SfM points + jittered copies, opacity 0.1" : args.checkpoint.c_str(),
        views.size(), args.iterations);
    std::printf("%-24s %10s %10s\n", "phase", "stage 1", "stage 3");
    for (int p = 0; p < kPhases; ++p)
        std::printf("%-24s %10.2f %10.2f\n", kPhaseNames[p], m1[std::size_t(p)], m3[std::size_t(p)]);
    std::printf("%-24s %10.2f %10.2f\n", "iteration", m1[kPhases], m3[kPhases]);
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
}
