// `lumigauss train <scene> -o <run>`: trains a relightable surfel model with the three-stage LumiGauss
// schedule, with a progress line, a JSON-lines log of every loss term, atomic checkpoints (at intervals, on
// Ctrl-C and before stopping on a non-finite value) and exact --resume. The run's life is the library's
// (train/training_run.h); this file parses the flags, prints, and turns Ctrl-C into a stop request.
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "commands.h"
#include "lumigauss/eval/holdout.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/train/trainer.h"
#include "lumigauss/train/training_run.h"
#include "lumigauss/util/error.h"

namespace lumigauss::cli {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) {
    g_interrupted = true;
}

struct TrainFlags {
    std::string scene, out, preset = "default", config_file, backend = "cpu";
    std::vector<std::string> overrides;
    std::int64_t iterations = 0, stop_after = 0;
    std::string downscale;  // -r: "auto", 1, 2, 4, 8; empty: the preset's (auto)
    int threads = 0;
    std::optional<int> test_every;
    bool resume = false, force = false, quiet = false, no_test = false;
};

double peak_memory_mib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

TrainConfig config_from_flags(const TrainFlags& f) {
    TrainConfig c = train_preset(f.preset);
    if (!f.config_file.empty()) apply_train_config_json(c, read_text_file(f.config_file), f.config_file);
    // --iterations scales the schedule so that a short run still reaches every stage; a --set key is taken
    // as given, after it.
    if (f.iterations > 0) scale_schedule(c, f.iterations);
    for (const auto& o : f.overrides) apply_train_config_override(c, o);
    if (!f.downscale.empty()) c.downscale = f.downscale == "auto" ? 0 : std::stoi(f.downscale);
    validate_train_config(c);
    return c;
}

class Progress {
  public:
    // `start`: the iteration the run (re)starts from, so that the first rate is not inflated on --resume.
    Progress(std::int64_t start, std::int64_t total, bool quiet)
        : total_(total), quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0), last_iteration_(start) {}

    void update(const StepReport& r, bool force) {
        psnr_.push_back(r.psnr > 0 ? r.psnr : psnr_.empty() ? 0 : psnr_.back());
        if (psnr_.size() > 50) psnr_.pop_front();
        const auto now = std::chrono::steady_clock::now();
        const double since = std::chrono::duration<double>(now - last_print_).count();
        const bool due = tty_ ? since > 0.25 : r.iteration % std::max<std::int64_t>(1, total_ / 20) == 0;
        if (quiet_ || (!due && !force)) return;
        const double rate = double(r.iteration - last_iteration_) / std::max(since, 1e-9);
        last_print_ = now;
        last_iteration_ = r.iteration;
        const double eta = rate > 0 ? double(total_ - r.iteration) / rate : 0;
        std::fprintf(
            stderr, "%s[%d %-10s] %6lld/%lld %3d%%  loss %.4f  psnr %5.2f  surfels %zu  %5.1f it/s  eta %s%s",
            tty_ ? "\r" : "", int(r.stage), stage_name(r.stage), (long long)r.iteration, (long long)total_,
            int(100 * r.iteration / std::max<std::int64_t>(total_, 1)), r.total, mean_psnr(), r.surfels, rate,
            duration(eta).c_str(), tty_ ? "\033[K" : "\n");
        std::fflush(stderr);
    }
    void finish() {
        if (tty_ && !quiet_) std::fprintf(stderr, "\n");
    }
    double mean_psnr() const {
        double s = 0;
        for (double p : psnr_) s += p;
        return psnr_.empty() ? 0 : s / double(psnr_.size());
    }
    static std::string duration(double seconds) {
        char buf[32];
        const auto t = (long long)seconds;
        std::snprintf(buf, sizeof buf, "%lld:%02lld:%02lld", t / 3600, t / 60 % 60, t % 60);
        return buf;
    }

  private:
    std::int64_t total_;
    bool quiet_, tty_;
    std::chrono::steady_clock::time_point last_print_ = std::chrono::steady_clock::now();
    std::int64_t last_iteration_;
    std::deque<double> psnr_;
};

// Up to four held-out photos of a snapshot (spread over the test split) scored as `eval --protocol holdout
// --fit-iterations 100` scores the shadowed render at the training resolution (each photo's light fitted
// through the network on its left half, the right half scored): a shorter fit, no unshadowed one and a few
// photos, so that training does not wait long (plaza, fast preset: 12 photos took 55-100 s per snapshot).
SnapshotScorer held_out_scorer(const std::string& scene, RasterBackend backend) {
    return [scene, backend](const RunPaths& paths) -> std::optional<HeldOutScore> {
        const TrainedRun run = load_trained_run(paths.dir);
        DatasetOptions dopt;
        dopt.downscale = run.downscale > 0 ? run.downscale : 1;
        const Dataset data = load_scene_of_run(paths.dir, scene, dopt);
        if (data.split(Split::Test).empty()) return std::nullopt;
        HoldoutOptions options;
        options.fit.variable = LightVariable::Embedding;
        options.fit.iterations = 100;
        options.keep_panels = false;
        options.unshadowed = false;  // one fit per photo: the shadowed render is the model
        options.max_views = 4;       // a trend to watch; `eval` scores them all
        options.backend = backend;
        const HoldoutResult result = evaluate_holdout(run, data, options);
        return HeldOutScore{result.images.size(), result.mean_shadowed.psnr};
    };
}

int run_train(const TrainFlags& f) {
    TrainingRunRequest request;
    request.backend = choose_backend(f.backend);  // before anything is read or written
    std::unique_ptr<tbb::global_control> threads;
    if (f.threads > 0)
        threads =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, f.threads);
    request.scene = f.scene, request.out = f.out;
    request.resume = f.resume, request.force = f.force;
    if (f.resume) {
        if (!f.config_file.empty() || !f.overrides.empty() || !f.downscale.empty() || f.test_every ||
            f.no_test)
            throw Error("--resume continues with the saved config and split; only --iterations may change");
        request.resume_iterations = f.iterations;
    } else {
        request.config = config_from_flags(f);
        if (f.no_test) request.test_every = 0;
        if (f.test_every) request.test_every = *f.test_every;
    }
    request.score_snapshot = held_out_scorer(f.scene, request.backend);
    TrainingRun run(request);
    const Trainer& trainer = run.trainer();
    const TrainConfig& config = trainer.state().config;
    const RunPaths& paths = run.paths();
    if (run.resumed())
        std::printf("train: resuming %s at iteration %lld of %lld\n", f.out.c_str(),
                    (long long)trainer.iteration(), (long long)config.iterations);
    else
        std::printf(
            "train: %zu photos (%zu more held out for testing), %zu SfM points, preset %s, %lld "
            "iterations -> %s\n",
            trainer.views().size(), run.held_out_photos(), run.sfm_points(), config.preset.c_str(),
            (long long)config.iterations, f.out.c_str());
    if (!run.auto_downscale_note().empty()) std::printf("train: %s\n", run.auto_downscale_note().c_str());
    if (!run.resumed()) {
        std::printf("train: %s\n", schedule_summary(config).c_str());
        if (config.iterations <= config.start_shadowed)
            std::printf(
                "train: warning: the run ends at iteration %lld, before the shadowed stage (%lld): its "
                "shadowed renders and shadows are not trained\n",
                (long long)config.iterations, (long long)config.start_shadowed + 1);
    }
    if (!run.resumed() && config.ground_seeds) {
        const GroundSeeds& g = trainer.ground();
        if (g.found)
            std::printf(
                "train: ground plane %.4g along the cameras' up, %zu SfM points on it: %zu starting points "
                "added where it is bare (grid %.3g)\n",
                g.height, g.ground_points, g.xyz.size(), g.spacing);
        else
            std::printf("train: no ground plane under the cameras in the SfM points: no ground seeds\n");
    }
    if (run.cameras_fitted_to_photos() > 0)
        std::printf(
            "train: %zu photos are smaller than their COLMAP camera (same aspect ratio): their "
            "cameras were scaled to them\n",
            run.cameras_fitted_to_photos());
    if (run.undistorted_photos() > 0)
        std::printf(
            "train: %zu photos have lens distortion: undistorted onto their pinhole camera as they load "
            "(pixels the photo does not cover are masked out)\n",
            run.undistorted_photos());
    for (const std::string& note : run.exif_notes()) std::printf("train: %s\n", note.c_str());
    if (!run.resumed() && config.exif_exposure) {
        const std::vector<float>& k = trainer.exposures();
        const auto [lo, hi] = std::minmax_element(k.begin(), k.end());
        std::printf(
            "train: exif_exposure: each photo's light is its EXIF exposure relative to the mean (x%.3g to "
            "x%.3g) times the lighting network's output\n",
            double(*lo), double(*hi));
    }
    if (run.far_points_dropped() > 0)
        std::printf(
            "train: dropped %zu SfM point(s) more than %.4g from the cameras' centre (1000x their "
            "extent: failed triangulations)\n",
            run.far_points_dropped(), run.far_point_limit());
    std::fflush(stdout);
    if (request.backend != RasterBackend::Cpu && !f.quiet)
        std::printf("train: rasterizing on %s\n", backend_description(request.backend).c_str());
    std::signal(SIGINT, on_interrupt);
    std::signal(SIGTERM, on_interrupt);
    Progress progress(trainer.iteration(), config.iterations, f.quiet);
    const TrainingOutcome outcome = run.run(
        f.stop_after, [] { return g_interrupted.load(); },
        [&](const StepReport& r) { progress.update(r, trainer.done()); });
    progress.finish();
    if (outcome == TrainingOutcome::Stopped) {
        std::printf("train: stopped at iteration %lld; checkpoint %s (continue with --resume)\n",
                    (long long)trainer.iteration(), paths.checkpoint.c_str());
        return g_interrupted ? 130 : 0;
    }
    if (outcome == TrainingOutcome::NonFinite) {
        std::fprintf(stderr,
                     "error: %s. Stopped; the last good state (iteration %lld) is in %s. Lower the learning "
                     "rates or check the input photos, then continue with --resume.\n",
                     run.failure().c_str(), (long long)trainer.iteration(), paths.checkpoint.c_str());
        return 3;
    }
    const auto& t = trainer.phase_times();
    std::printf(
        "train: done, %lld iterations in %s, %zu surfels, training PSNR %.2f dB (last 50), peak memory %.0f "
        "MiB\n",
        (long long)config.iterations, Progress::duration(run.elapsed_seconds()).c_str(),
        trainer.state().model.size(), progress.mean_psnr(), peak_memory_mib());
    std::printf(
        "train: time in shading %.1fs, raster fwd %.1fs, losses %.1fs, raster bwd %.1fs, shading bwd %.1fs, "
        "physical %.1fs, optimizer %.1fs, densify %.1fs\n",
        t.shading, t.raster_forward, t.losses, t.raster_backward, t.shading_backward, t.physical, t.optimizer,
        t.densify);
    if (const HeldOutLog& h = run.last_held_out(); h.score)
        std::printf(
            "train: %zu held-out photos: PSNR %.2f dB (each light fitted on the left half, the right half "
            "scored; %.1f s; `eval` scores them all)\n",
            h.score->photos, h.score->psnr, h.seconds);
    else if (!h.error.empty())
        std::printf("train: the held-out photos could not be scored: %s\n", h.error.c_str());
    std::printf("train: model %s, lighting %s, photos %s\n", paths.model.c_str(), paths.lighting.c_str(),
                paths.appearance.c_str());
    return 0;
}

}  // namespace

void register_train(CLI::App& app) {
    auto f = std::make_shared<TrainFlags>();
    CLI::App* cmd = app.add_subcommand(
        "train",
        "Train a relightable surfel model (LumiGauss, three stages) from photos under many lightings");
    cmd->add_option("scene", f->scene, "Dataset folder (COLMAP layout with sparse/0 and images/)")
        ->required();
    cmd->add_option("-o,--output", f->out, "Run folder (model, lighting, config, log, checkpoint)")
        ->required();
    cmd->add_option("--preset", f->preset,
                    "default (40k iterations, sky and floater handling), fast (3k, small scenes), paper (the "
                    "official LumiGauss, for reproducing it) or paper-fast")
        ->check(CLI::IsMember(train_preset_names()))
        ->capture_default_str();
    cmd->add_option("--iterations", f->iterations,
                    "Total iterations; the preset's schedule (stages, densification, resets) scales with it "
                    "(with --resume: only extends the run)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("-r,--resolution,--downscale", f->downscale,
                    "Downscale the photos by 1, 2, 4 or 8; auto (the default) takes the smallest factor that "
                    "brings the longest photo side to at most 1600 px, and says so")
        ->check(CLI::IsMember({"auto", "1", "2", "4", "8"}));
    cmd->add_option("--config", f->config_file, "JSON file with config keys (see the run's config.json)");
    cmd->add_option("--set", f->overrides, "Override one config key: --set lambda_shadow=5 (repeatable)");
    auto* every = cmd->add_option("--test-every", f->test_every,
                                  "Every N-th photo by name is held out as a test photo, the others train, "
                                  "whatever the scene's split file says (default: the split file, else every "
                                  "8th). Recorded in the run: render and eval then use this split")
                      ->check(CLI::PositiveNumber);
    cmd->add_flag("--no-test", f->no_test, "Train on every photo, test photos of the split file included")
        ->excludes(every);
    cmd->add_flag("--resume", f->resume, "Continue the run in the output folder from its checkpoint");
    cmd->add_flag("--force", f->force, "Replace an existing run in the output folder");
    cmd->add_option("--stop-after", f->stop_after, "Checkpoint and stop after this iteration (resume later)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--threads", f->threads, "Worker threads (default: all cores)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--backend", f->backend,
                    "Rasterize (forward and backward) on the CPU or on the GPU (cuda: builds with the CUDA "
                    "backend, on a machine with a GPU; auto: the GPU when there is one); the rest of each "
                    "iteration runs on the CPU")
        ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", f->quiet, "No progress line");
    cmd->callback([f] {
        const int rc = run_train(*f);
        if (rc != 0) throw CLI::RuntimeError(rc);
    });
}

}  // namespace lumigauss::cli
