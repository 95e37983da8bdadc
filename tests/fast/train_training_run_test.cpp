// The training run's life in its folder (train/training_run.h): a replaced run (--force) leaves nothing of
// the old one that --resume could pick up, and a refused start changes nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fast/io_test_util.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/ply.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/synth/synth.h"
#include "lumigauss/train/checkpoint.h"
#include "lumigauss/train/training_run.h"
#include "lumigauss/util/error.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using synth_test::TempDir;

const std::string& tiny_scene() {
    static TempDir dir("training_run_scene");
    static const std::string root = [] {
        synth::generate_synthetic_scene(synth_test::tiny_options(dir.str()));
        return dir.str();
    }();
    return root;
}

TrainingRunRequest request(const std::string& out, std::int64_t iterations) {
    TrainingRunRequest r;
    r.scene = tiny_scene();
    r.out = out;
    r.config = train_preset("fast");
    r.config.iterations = iterations;
    return r;
}

void write_text(const fs::path& path, const std::string& text) {
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
}

// The tiny COLMAP scene rewritten in the NeRF-OSR layout (final/{train,test}/{rgb,pose,intrinsics}/), without
// its SfM points.
std::string tiny_scene_as_nerfosr(const TempDir& tmp) {
    const Dataset colmap = load_dataset(tiny_scene());
    const fs::path final_dir = fs::path(tmp.str()) / "nerfosr" / "final";
    for (const View& v : colmap.views) {
        const fs::path split = final_dir / (v.split == Split::Test ? "test" : "train");
        const std::string stem = fs::path(v.name).stem().string();
        fs::create_directories(split / "rgb");
        fs::copy_file(v.image_path, split / "rgb" / fs::path(v.image_path).filename());
        const Camera& c = v.camera;
        const Vec3d centre = c.center();
        std::string pose;
        for (int i = 0; i < 3; ++i)
            pose += std::to_string(c.rotation(0, i)) + " " + std::to_string(c.rotation(1, i)) + " " +
                    std::to_string(c.rotation(2, i)) + " " + std::to_string(centre[i]) + "\n";
        write_text(split / "pose" / (stem + ".txt"), pose + "0 0 0 1\n");
        write_text(split / "intrinsics" / (stem + ".txt"),
                   std::to_string(c.fx) + " 0 " + std::to_string(c.cx) + " 0 " + std::to_string(c.fy) + " " +
                       std::to_string(c.cy) + " 0 0 1");
    }
    return final_dir.parent_path().string();
}

TEST(TrainingRun, ANerfOsrSceneTrainsFromItsPointCloud) {
    TempDir tmp("training_run_nerfosr");
    TrainingRunRequest r = request(tmp / "run", 3);
    r.scene = tiny_scene_as_nerfosr(tmp);
    const std::string points = (fs::path(r.scene) / "final" / "points3d.ply").string();
    try {
        TrainingRun run(r);
        ADD_FAILURE() << "a scene without SfM points was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(points), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("SfM points"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(fs::path(r.out) / "config.json")) << "a refused run left files";

    const Dataset colmap = load_dataset(tiny_scene());
    PlyVertexTable table;
    table.count = colmap.point_xyz.size();
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<float> xyz, rgb;
        for (std::size_t i = 0; i < table.count; ++i) {
            xyz.push_back(colmap.point_xyz[i][axis]);
            rgb.push_back(std::round(255 * colmap.point_rgb[i][axis]));
        }
        table.add(std::string(1, "xyz"[axis]), std::move(xyz));
        table.add(std::array{"red", "green", "blue"}[std::size_t(axis)], std::move(rgb));
    }
    write_ply_vertices(points, table);
    const Dataset nerfosr = load_dataset(r.scene);
    EXPECT_EQ(nerfosr.points_path, points);
    ASSERT_EQ(nerfosr.point_xyz.size(), colmap.point_xyz.size());
    EXPECT_NEAR(nerfosr.point_rgb[0].y, colmap.point_rgb[0].y, 0.5 / 255);
    TrainingRun run(r);
    EXPECT_EQ(run.run(
                  0, [] { return false; }, [](const StepReport&) {}),
              TrainingOutcome::Finished);
}

// -r auto (downscale 0, every preset's default) trains large photos at the smallest of 1/2/4/8 that brings
// the longest side to at most 1600 px, records the factor, and says so; an explicit factor is kept.
TEST(TrainingRun, AutoResolutionDownscalesLargePhotos) {
    TempDir tmp("training_run_auto_resolution");
    test::write_scene(tmp / "scene", test::small_model(3, 3300, 24));  // 3300 px wide: 1/4 -> 825
    TrainingRunRequest r = request(tmp / "run", 2);
    r.scene = tmp / "scene";
    ASSERT_EQ(r.config.downscale, 0) << "presets default to auto";
    {
        TrainingRun run(r);
        EXPECT_EQ(run.trainer().state().config.downscale, 4);
        EXPECT_EQ(run.trainer().views().front().camera.width, 825);
        EXPECT_NE(run.auto_downscale_note().find("1/4"), std::string::npos) << run.auto_downscale_note();
    }
    EXPECT_NE(read_text_file(run_paths(r.out).config).find("\"downscale\": 4"), std::string::npos);
    r.config.downscale = 1;
    r.force = true;
    TrainingRun full(r);
    EXPECT_EQ(full.trainer().views().front().camera.width, 3300);
    EXPECT_TRUE(full.auto_downscale_note().empty());
    r.scene = tiny_scene();
    r.config.downscale = 0;
    EXPECT_TRUE(TrainingRun(r).auto_downscale_note().empty()) << "small photos stay at full size";
}

TEST(TrainingRun, ForceRemovesThePreviousRunBeforeTheNewOneCheckpoints) {
    TempDir tmp("training_run_force");
    const std::string out = tmp / "run";
    {
        TrainingRun first(request(out, 8));
        ASSERT_EQ(first.run(
                      0, [] { return false; }, [](const StepReport&) {}),
                  TrainingOutcome::Finished);
    }
    const RunPaths paths = run_paths(out);
    for (const std::string* f : {&paths.checkpoint, &paths.model, &paths.lighting, &paths.appearance})
        ASSERT_TRUE(fs::exists(*f)) << *f;
    ASSERT_TRUE(fs::exists(fs::path(out) / "previews"));
    fs::create_directories(fs::path(out) / "mine");  // not the run's: stays

    EXPECT_THROW(TrainingRun(request(out, 20)), Error);  // no --force: refused, nothing touched
    EXPECT_TRUE(fs::exists(paths.checkpoint));

    TrainingRunRequest forced = request(out, 20);
    forced.force = true;
    TrainingRun second(forced);  // started, not yet run: as if it crashed before its first checkpoint
    for (const std::string* f : {&paths.checkpoint, &paths.model, &paths.lighting, &paths.appearance})
        EXPECT_FALSE(fs::exists(*f)) << *f << " of the replaced run is still there";
    EXPECT_FALSE(fs::exists(fs::path(out) / "previews"));
    EXPECT_TRUE(fs::exists(fs::path(out) / "mine"));
    TrainingRunRequest resume = request(out, 0);
    resume.resume = true;
    EXPECT_THROW(TrainingRun{resume}, Error) << "--resume found a checkpoint of the replaced run";

    ASSERT_EQ(second.run(
                  0, [] { return false; }, [](const StepReport&) {}),
              TrainingOutcome::Finished);
    EXPECT_EQ(load_checkpoint(paths.checkpoint).iteration, 20);
}

// A stopped run (--stop-after, Ctrl-C) could be resumed but not looked at: model.ply appeared only at the
// end. The snapshot written with the checkpoint opens as a run and holds the checkpoint's surfels.
TEST(TrainingRun, AStoppedRunCanBeOpened) {
    TempDir tmp("training_run_snapshot");
    const std::string out = tmp / "run";
    TrainingRun run(request(out, 20));
    ASSERT_EQ(run.run(
                  7, [] { return false; }, [](const StepReport&) {}),
              TrainingOutcome::Stopped);
    const TrainState checkpoint = load_checkpoint(run_paths(out).checkpoint);
    ASSERT_EQ(checkpoint.iteration, 7);
    const TrainedRun opened = load_trained_run(out);
    ASSERT_EQ(opened.model.size(), checkpoint.model.size());
    for (const ModelParam p : kAllModelParams)
        EXPECT_EQ(opened.model.param(p), checkpoint.model.param(p)) << "parameter " << int(p);
    EXPECT_EQ(opened.image_names, checkpoint.image_names);
}

std::vector<nlohmann::json> log_lines(const std::string& path) {
    std::vector<nlohmann::json> lines;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
    return lines;
}

// The scorer sees the model files of every held_out_interval-th iteration and of the end once they are
// written (with or without a checkpoint there), its scores go into that iteration's log line, and
// held_out_interval = 0 turns it off.
TEST(TrainingRun, HeldOutScoresGoIntoTheLogEveryInterval) {
    TempDir tmp("training_run_held_out");
    TrainingRunRequest r = request(tmp / "run", 25);
    // Checkpoints only at the end: the scored snapshots at 10 and 20 are model files only.
    r.config.checkpoint_interval = 0;
    r.config.held_out_interval = 10;
    r.config.warmup = 4, r.config.start_shadowed = 5;  // scored in the shadowed stage: from iteration 6
    r.config.log_interval = 4;      // 10 and 25 are not logged iterations: scoring logs them anyway
    std::vector<std::size_t> seen;  // the surfel count of each scored snapshot
    r.score_snapshot = [&](const RunPaths& paths) -> std::optional<HeldOutScore> {
        seen.push_back(load_trained_run(paths.dir).model.size());
        return HeldOutScore{3, 10.0 * double(seen.size())};
    };
    TrainingRun run(r);
    ASSERT_EQ(run.run(
                  0, [] { return false; }, [](const StepReport&) {}),
              TrainingOutcome::Finished);
    ASSERT_EQ(seen.size(), 3u);
    EXPECT_EQ(seen.back(), run.trainer().state().model.size());
    std::vector<std::int64_t> scored;
    for (const nlohmann::json& j : log_lines(run.paths().log))
        if (j.contains("held_out_psnr")) {
            scored.push_back(j["iteration"]);
            EXPECT_EQ(j["held_out_psnr"], 10.0 * double(scored.size()));
            EXPECT_EQ(j["held_out_photos"], 3);
            EXPECT_TRUE(j["held_out_s"].is_number());
        }
    EXPECT_EQ(scored, (std::vector<std::int64_t>{10, 20, 25}));
    ASSERT_TRUE(run.last_held_out().score.has_value());
    EXPECT_EQ(run.last_held_out().score->psnr, 30.0);

    seen.clear();
    r.out = tmp / "off";
    r.config.held_out_interval = 0;
    TrainingRun off(r);
    ASSERT_EQ(off.run(
                  0, [] { return false; }, [](const StepReport&) {}),
              TrainingOutcome::Finished);
    EXPECT_TRUE(seen.empty());
    for (const nlohmann::json& j : log_lines(off.paths().log)) EXPECT_FALSE(j.contains("held_out_psnr"));
}

// A scorer that fails is reported once in the log and never stops the training.
TEST(TrainingRun, AFailingScorerIsReportedOnceAndTrainingGoesOn) {
    TempDir tmp("training_run_scorer_fails");
    TrainingRunRequest r = request(tmp / "run", 25);
    r.config.held_out_interval = 10;
    r.config.warmup = 4, r.config.start_shadowed = 5;
    int calls = 0;
    r.score_snapshot = [&](const RunPaths&) -> std::optional<HeldOutScore> {
        ++calls;
        throw Error("test photo x.png: no pixel to score");
    };
    TrainingRun run(r);
    ASSERT_EQ(run.run(
                  0, [] { return false; }, [](const StepReport&) {}),
              TrainingOutcome::Finished);
    EXPECT_EQ(calls, 1);
    int errors = 0;
    for (const nlohmann::json& j : log_lines(run.paths().log))
        if (j.contains("held_out_error")) {
            ++errors;
            EXPECT_EQ(j["iteration"], 10);
            EXPECT_NE(j["held_out_error"].get<std::string>().find("x.png"), std::string::npos);
        }
    EXPECT_EQ(errors, 1);
    EXPECT_TRUE(fs::exists(run.paths().model));
}

// A damaged log line must not block --resume (it stopped it with "internal error: stoll" before): the
// checkpoint is the state; the log keeps its readable lines up to the checkpoint.
TEST(TrainingRun, ResumeCutsTheLogAndDropsDamagedLines) {
    TempDir tmp("training_run_log");
    const std::string log = tmp / "log.jsonl";
    std::ofstream(log)
        << ("{\"iteration\":5,\"total\":1}\n"
            "{\"iteration\":garbage}\n"
            "{\"iteration\":10,\"tot\n"
            "{\"iteration\":15,\"total\":1}\n"
            "not json at all\n");
    truncate_log(log, 10);
    EXPECT_EQ(synth_test::read_bytes(log), "{\"iteration\":5,\"total\":1}\n");
}

}  // namespace
}  // namespace lumigauss
