#pragma once
// The life of a training run in its folder (model/run_files.h): start it (config.json, an empty log) or
// resume it from its checkpoint (the log cut back to the checkpoint's iteration), train with a log line at
// the config's cadence and checkpoints at its interval, stop with a checkpoint when asked to or after a given
// iteration, and on a non-finite value keep the last good state. Every checkpoint also writes the model
// files (a snapshot that render, eval, export and view open); a finished run adds its previews. `lumigauss
// train` only parses flags and prints around it.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/model/run_files.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/train/run_folder.h"
#include "lumigauss/train/train_config.h"
#include "lumigauss/train/trainer.h"

namespace lumigauss {

// Scores the model files a snapshot has just written (paths), or returns nothing (no photo to score). The
// protocol is the caller's: `train` passes eval's holdout protocol, which train/ cannot include.
using SnapshotScorer = std::function<std::optional<HeldOutScore>(const RunPaths& paths)>;

struct TrainingRunRequest {
    std::string scene, out;
    bool resume = false;
    bool force = false;                  // a new run may replace a run already in `out`
    TrainConfig config;                  // a new run's configuration (a resumed run keeps its own)
    std::int64_t resume_iterations = 0;  // resume only: > 0 sets a new total (not below the checkpoint's)
    RasterBackend backend = RasterBackend::Cpu;
    // A new run's split override (DatasetOptions::test_every): set, every n-th photo is a test photo (0:
    // none). A resumed run keeps the split it recorded (scene.json).
    std::optional<int> test_every;
    // Called every config.held_out_interval iterations of the shadowed stage and at the end (never when it is
    // 0), once the model files of that iteration are written; its scores go into log.jsonl with that
    // iteration's line
    // ("held_out_psnr", "held_out_photos", "held_out_s"). One that throws is reported in the log
    // ("held_out_error") and not called again: scoring never stops a training run.
    SnapshotScorer score_snapshot;
};

enum class TrainingOutcome {
    Finished,   // every iteration ran; model, lighting, appearance and previews written
    Stopped,    // stopped at stop_after or when asked to; checkpoint and model snapshot written
    NonFinite,  // a loss or gradient was not finite; the last good state is in the checkpoint
};

class TrainingRun {
  public:
    // Starts or resumes. Throws Error naming the file or the flag when the run cannot (no checkpoint to
    // resume, a run already there without force, a smaller total than the checkpoint's, a bad dataset);
    // then nothing in `out` has changed.
    explicit TrainingRun(const TrainingRunRequest& request);
    ~TrainingRun();

    // Trains until the run is done, `stop_after` (> 0) is reached, or `stop_requested` returns true
    // (checked before every iteration); `on_step` sees every iteration's report.
    TrainingOutcome run(std::int64_t stop_after, const std::function<bool()>& stop_requested,
                        const std::function<void(const StepReport&)>& on_step);

    const Trainer& trainer() const { return *trainer_; }
    const RunPaths& paths() const { return paths_; }
    bool resumed() const { return resumed_; }
    std::size_t sfm_points() const { return sfm_points_; }
    std::size_t held_out_photos() const { return held_out_photos_; }  // the scene's test/validation photos
    // What -r auto chose, when it downscaled the photos (empty otherwise).
    const std::string& auto_downscale_note() const { return auto_note_; }
    // SfM points the dataset dropped for lying absurdly far from the cameras, and beyond what distance.
    std::size_t far_points_dropped() const { return far_points_dropped_; }
    std::size_t cameras_fitted_to_photos() const { return cameras_fitted_; }  // Dataset's, of a new run
    std::size_t undistorted_photos() const {
        return undistorted_;
    }  // Dataset::undistorted_views, of a new run
    double far_point_limit() const { return far_point_limit_; }
    // What the photos' EXIF meant (io/exif_notes.h), of a new run.
    const std::vector<std::string>& exif_notes() const { return exif_notes_; }
    // The message of the non-finite value that ended run() (TrainingOutcome::NonFinite).
    const std::string& failure() const { return failure_; }
    double elapsed_seconds() const;  // in run(), this process
    // The held-out scores of the latest snapshot scored in run() (no score before one, or without a scorer).
    const HeldOutLog& last_held_out() const { return last_held_out_; }

  private:
    void save_checkpoint_and_snapshot();
    // The held-out scores of the snapshot just written (nothing without a scorer or when scoring is off).
    HeldOutLog score_snapshot();

    RunPaths paths_;
    std::unique_ptr<Trainer> trainer_;
    bool resumed_ = false;
    std::size_t sfm_points_ = 0, held_out_photos_ = 0;
    std::string auto_note_;
    std::size_t far_points_dropped_ = 0, cameras_fitted_ = 0, undistorted_ = 0;
    std::vector<std::string> exif_notes_;
    double far_point_limit_ = 0;
    std::string failure_;
    double elapsed_ = 0;
    SnapshotScorer scorer_;
    HeldOutLog last_held_out_;
};

// Keeps the log lines up to `iteration` (a resumed run rewrites what followed its checkpoint); lines that are
// not a JSON object with an integer "iteration" are dropped.
void truncate_log(const std::string& path, std::int64_t iteration);

// dir/NAME.png for the first `count` training photos: the photo, the shadowed and the unshadowed render under
// the photo's learned environment (with its sky when trained with it), side by side, clipped to [0, 1].
void write_previews(const std::string& dir, const Trainer& trainer, int count);

// RUN/progress/ITERATION.png (the previews of the first `count` training views stacked, halved while wider
// than 960 px) and RUN/progress.html (train/progress_report.h) for the trainer's current iteration.
void write_progress(const RunPaths& paths, const Trainer& trainer, int count);

}  // namespace lumigauss
