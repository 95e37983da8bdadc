#include "lumigauss/train/training_run.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/exif_notes.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/render/background.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/train/checkpoint.h"
#include "lumigauss/train/progress_report.h"
#include "lumigauss/train/run_folder.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/text.h"

namespace lumigauss {

namespace {

// The training photos shown in previews/ and progress/.
constexpr int kPreviewViews = 4;

// What a replaced run (--force) leaves must not outlive it: a crash before the new run's first checkpoint
// followed by --resume would otherwise continue the old run under the new config. Only the run's own files
// go; anything else in the folder stays.
void remove_previous_run(const RunPaths& paths) {
    namespace fs = std::filesystem;
    for (const std::string* f :
         {&paths.checkpoint, &paths.model, &paths.lighting, &paths.appearance, &paths.sky, &paths.scene})
        fs::remove(*f);
    fs::remove_all(fs::path(paths.dir) / "previews");
    fs::remove_all(fs::path(paths.dir) / "progress");
    fs::remove(fs::path(paths.dir) / "progress.html");
}

// -r auto: the smallest factor of 1, 2, 4, 8 that brings the longest photo side to kAutoMaxPhotoSide (8 if
// none does); `note` says what was chosen when it is not 1.
int auto_downscale(const Dataset& data, std::string& note) {
    int longest = 0;
    for (const View& v : data.views) longest = std::max({longest, v.camera.width, v.camera.height});
    int factor = 1;
    while (factor < 8 && longest > factor * kAutoMaxPhotoSide) factor *= 2;
    if (factor > 1)
        note = "photos up to " + std::to_string(longest) + " px on their longest side: training at 1/" +
               std::to_string(factor) + " resolution (-r auto keeps the longest side at most " +
               std::to_string(kAutoMaxPhotoSide) + " px; -r 1 trains at full size)";
    return factor;
}

// Training starts from SfM points; a scene without any says where they were looked for.
[[noreturn]] void fail_without_points(const Dataset& data) {
    if (data.format == "nerf-osr")
        fail_in_file(
            data.points_path,
            "not found: training starts from SfM points, and this NeRF-OSR scene has none. Put them "
            "there as a PLY of vertices x y z [red green blue] in the poses' world (NeuSky's NeRF-OSR "
            "overlay ships final/points3d.ply), or train on the COLMAP layout of the scene "
            "(LumiGauss's processed NeRF-OSR release: images/, sparse/0/)");
    fail_in_file(data.points_path.empty() ? data.root : data.points_path,
                 "training starts from SfM points, and the scene has none");
}

}  // namespace

TrainingRun::TrainingRun(const TrainingRunRequest& request)
    : paths_(run_paths(request.out)), scorer_(request.score_snapshot) {
    if (request.resume) {
        if (!std::filesystem::exists(paths_.checkpoint))
            fail_in_file(paths_.checkpoint, "no checkpoint to resume from (start the run without --resume)");
        TrainState state = load_checkpoint(paths_.checkpoint);
        if (request.resume_iterations > 0) {
            if (request.resume_iterations < state.iteration)
                fail_in_file(paths_.checkpoint, "the run is already at iteration " +
                                                    std::to_string(state.iteration) +
                                                    "; --iterations must not be smaller");
            state.config.iterations = request.resume_iterations;
        }
        DatasetOptions dopt;
        dopt.downscale = state.config.downscale;
        const Dataset data = load_scene_of_run(request.out, request.scene, dopt);  // its poses and split
        sfm_points_ = data.point_xyz.size();
        held_out_photos_ = data.views.size() - data.split(Split::Train).size();
        trainer_ = std::make_unique<Trainer>(load_train_views(data), std::move(state));
        truncate_log(paths_.log, trainer_->iteration());
        resumed_ = true;
    } else {
        if (std::filesystem::exists(paths_.checkpoint) && !request.force)
            fail_in_file(paths_.checkpoint,
                         "a run already exists here; continue it with --resume or replace it with --force");
        TrainConfig config = request.config;
        DatasetOptions dopt;
        dopt.test_every = request.test_every;
        if (config.downscale == 0) {  // auto: from the photos' sizes (headers only; pixels load lazily)
            dopt.downscale = 1;
            config.downscale = auto_downscale(load_dataset(request.scene, dopt), auto_note_);
        }
        dopt.downscale = config.downscale;
        const Dataset data = load_dataset(request.scene, dopt);
        if (data.point_xyz.empty()) fail_without_points(data);
        sfm_points_ = data.point_xyz.size();
        held_out_photos_ = data.views.size() - data.split(Split::Train).size();
        far_points_dropped_ = data.far_points_dropped;
        cameras_fitted_ = data.cameras_fitted_to_photos;
        undistorted_ = data.undistorted_views();
        exif_notes_ = lumigauss::exif_notes(data);
        far_point_limit_ = data.far_point_limit;
        trainer_ = std::make_unique<Trainer>(load_train_views(data), data.point_xyz, data.point_rgb, config);
        std::filesystem::create_directories(request.out);  // only once the input is known to be good
        remove_previous_run(paths_);
        write_file_atomically(paths_.config, train_config_to_json(config));
        save_scene_record(paths_.scene, scene_record_of(data));
        write_file_atomically(paths_.log, "");
    }
    trainer_->set_backend(request.backend);
}

TrainingRun::~TrainingRun() = default;

// The checkpoint resumes the run; the model files beside it let render, eval, export and view open a run
// that is still training, was stopped or was interrupted (each file is replaced atomically).
void TrainingRun::save_checkpoint_and_snapshot() {
    save_checkpoint(paths_.checkpoint, trainer_->state());
    save_run_model(paths_, trainer_->state(), trainer_->exposures());
}

double TrainingRun::elapsed_seconds() const {
    return elapsed_;
}

HeldOutLog TrainingRun::score_snapshot() {
    HeldOutLog held_out;
    if (!scorer_) return held_out;
    const auto t0 = std::chrono::steady_clock::now();
    try {
        held_out.score = scorer_(paths_);
    } catch (const std::exception& e) {
        held_out.error = e.what();
        scorer_ = nullptr;  // reported once; the training goes on
    }
    held_out.seconds = seconds_since(t0);
    last_held_out_ = held_out;
    return held_out;
}

TrainingOutcome TrainingRun::run(std::int64_t stop_after, const std::function<bool()>& stop_requested,
                                 const std::function<void(const StepReport&)>& on_step) {
    const TrainConfig& config = trainer_->state().config;
    std::ofstream log(paths_.log, std::ios::app);
    const auto t0 = std::chrono::steady_clock::now();
    const double before = elapsed_;
    const auto elapsed = [&] { return before + seconds_since(t0); };
    while (!trainer_->done()) {
        if (stop_requested() || (stop_after > 0 && trainer_->iteration() >= stop_after)) {
            save_checkpoint_and_snapshot();
            write_progress(paths_, *trainer_, kPreviewViews);
            elapsed_ = elapsed();
            return TrainingOutcome::Stopped;
        }
        StepReport r;
        try {
            r = trainer_->step();
        } catch (const NonFiniteError& e) {
            save_checkpoint(paths_.checkpoint, trainer_->state());
            failure_ = e.what();
            elapsed_ = elapsed();
            return TrainingOutcome::NonFinite;
        }
        // The held-out photos are scored on a snapshot of the model files, before the iteration's log line
        // (which carries the scores) and the progress report (whose charts read the log).
        const bool done = trainer_->done();
        const bool checkpoint_now =
            config.checkpoint_interval > 0 && r.iteration % config.checkpoint_interval == 0 && !done;
        // Before the shadowed stage the shadowed render (what is scored) is not trained yet: the end only.
        const bool score_now =
            config.held_out_interval > 0 &&
            ((r.iteration % config.held_out_interval == 0 && r.iteration > config.start_shadowed) || done);
        if (checkpoint_now || done)
            save_checkpoint_and_snapshot();
        else if (score_now)
            save_run_model(paths_, trainer_->state(), trainer_->exposures());
        HeldOutLog held_out;
        if (score_now) held_out = score_snapshot();
        const bool log_now = r.iteration % config.log_interval == 0 || r.densify_ran || r.prune_ran ||
                             r.empty_space_swept || done || held_out.score || !held_out.error.empty();
        if (log_now) log << step_log_line(r, elapsed(), held_out) << '\n' << std::flush;
        if (checkpoint_now) write_progress(paths_, *trainer_, kPreviewViews);
        on_step(r);
    }
    write_previews((std::filesystem::path(paths_.dir) / "previews").string(), *trainer_, kPreviewViews);
    write_progress(paths_, *trainer_, kPreviewViews);
    elapsed_ = elapsed();
    return TrainingOutcome::Finished;
}

void truncate_log(const std::string& path, std::int64_t iteration) {
    std::ifstream in(path);
    if (!in) return;
    std::string kept, line;
    while (std::getline(in, line)) {
        // A damaged line (a crash mid-write, an edit) is dropped: the checkpoint, not the log, is the state,
        // so it must not stop the run from resuming.
        const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
        if (j.is_object() && j.contains("iteration") && j["iteration"].is_number_integer() &&
            j["iteration"].get<std::int64_t>() <= iteration)
            kept += line + "\n";
    }
    write_file_atomically(path, kept);
}

namespace {

// Photo | shadowed | unshadowed of training view v under its learned light (over its sky when trained so).
Image preview_image(const Trainer& trainer, int v) {
    const TrainView& view = trainer.views()[std::size_t(v)];
    const TrainState& st = trainer.state();
    const ShCoeffs<float> env = trainer.environment(v);
    RasterImages<float> img = render_with_environment(st.model, view.camera, env, ShadingMode::Both,
                                                      RasterBackend::Cpu, trainer.side_rule());
    if (st.config.sky_background) {
        const Sh4Coeffs<float> residual =
            st.sky_residuals.empty() ? Sh4Coeffs<float>{} : st.sky_residuals.get(v);
        const Image sky = sky_image(view.camera, env, st.sky_residuals.empty() ? nullptr : &residual,
                                    trainer.sky_horizon());
        for (int first : {kShadowedOffset, kUnshadowedOffset})
            composite_background<float>(img, sky.pixels, first);
    }
    const Image shadowed = raster_channels(img, kShadowedOffset, 3);
    const Image unshadowed = raster_channels(img, kUnshadowedOffset, 3);
    const Image* panels[3] = {&view.rgb, &shadowed, &unshadowed};
    const int w = view.rgb.width, h = view.rgb.height;
    Image out(3 * w, h, 3);
    for (int k = 0; k < 3; ++k)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c)
                    out.at(k * w + x, y, c) = std::clamp(panels[k]->at(x, y, c), 0.0f, 1.0f);
    return out;
}

// Half the size, 2x2 box filter (odd edges dropped).
Image halved(const Image& im) {
    Image out(std::max(im.width / 2, 1), std::max(im.height / 2, 1), im.channels);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < im.channels; ++c) {
                const int x0 = std::min(2 * x, im.width - 1), y0 = std::min(2 * y, im.height - 1);
                const int x1 = std::min(x0 + 1, im.width - 1), y1 = std::min(y0 + 1, im.height - 1);
                out.at(x, y, c) =
                    0.25f * (im.at(x0, y0, c) + im.at(x1, y0, c) + im.at(x0, y1, c) + im.at(x1, y1, c));
            }
    return out;
}

}  // namespace

void write_previews(const std::string& dir, const Trainer& trainer, int count) {
    const auto& views = trainer.views();
    std::filesystem::create_directories(dir);
    for (int v = 0; v < std::min<int>(count, int(views.size())); ++v) {
        std::filesystem::path name = std::filesystem::path(dir) / views[std::size_t(v)].name;
        name.replace_extension(".png");
        std::filesystem::create_directories(name.parent_path());
        write_png(name.string(), preview_image(trainer, v));
    }
}

void write_progress(const RunPaths& paths, const Trainer& trainer, int count) {
    namespace fs = std::filesystem;
    std::vector<Image> rows;
    int width = 0, height = 0;
    for (int v = 0; v < std::min<int>(count, int(trainer.views().size())); ++v) {
        Image im = preview_image(trainer, v);
        while (im.width > 960) im = halved(im);
        width = std::max(width, im.width), height += im.height;
        rows.push_back(std::move(im));
    }
    const fs::path dir = fs::path(paths.dir) / "progress";
    fs::create_directories(dir);
    if (!rows.empty()) {
        Image sheet(width, height, 3);
        int top = 0;
        for (const Image& im : rows) {
            for (int y = 0; y < im.height; ++y)
                for (int x = 0; x < im.width; ++x)
                    for (int c = 0; c < 3; ++c) sheet.at(x, top + y, c) = im.at(x, y, c);
            top += im.height;
        }
        char name[32];
        std::snprintf(name, sizeof name, "%07lld.png", static_cast<long long>(trainer.iteration()));
        write_png((dir / name).string(), sheet);
    }
    std::vector<std::string> images;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".png") images.push_back("progress/" + e.path().filename().string());
    std::sort(images.begin(), images.end());
    std::ifstream log(paths.log);
    std::ostringstream text;
    text << log.rdbuf();
    write_file_atomically((fs::path(paths.dir) / "progress.html").string(),
                          progress_report_html(fs::path(paths.dir).filename().string(), text.str(), images));
}

}  // namespace lumigauss
