// A run remembers its scene (RUN/scene.json, model/scene_record.h): `eval` and `render` find it without
// --scene, and a scene whose photos of the same names were taken from other cameras is refused, where it
// used to be evaluated silently.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "lumigauss/io/dataset.h"
#include "lumigauss/model/run_files.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/util/error.h"
#include "support/run_cli.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using testing::CommandResult;
using ::testing::HasSubstr;
using testing::run_lumigauss;
using testing::shell_quoted;
namespace fs = std::filesystem;

std::string read_all(const std::string& path) {
    std::ifstream in(path);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// The same scene with the first image's camera moved 1 unit along x (COLMAP text: "ID QW QX QY QZ TX ...").
void move_first_camera(const std::string& scene) {
    const std::string path = scene + "/sparse/0/images.txt";
    std::istringstream in(read_all(path));
    std::string line, out;
    bool moved = false;
    while (std::getline(in, line)) {
        if (!moved && !line.empty() && line[0] != '#') {
            std::istringstream fields(line);
            std::string id, qw, qx, qy, qz, tx, rest;
            fields >> id >> qw >> qx >> qy >> qz >> tx;
            std::getline(fields, rest);
            line = id + " " + qw + " " + qx + " " + qy + " " + qz + " " +
                   std::to_string(std::stod(tx) + 1.0) + rest;
            moved = true;
        }
        out += line + "\n";
    }
    std::ofstream(path) << out;
}

TEST(SceneRecord, RoundTripAndPoseCheck) {
    TempDir tmp("scene_record_unit");
    const std::string scene = tmp / "scene";
    synth::generate_synthetic_scene(synth_test::tiny_options(scene));
    const Dataset d = load_dataset(scene);
    const SceneRecord r = scene_record_of(d);
    EXPECT_TRUE(fs::path(r.scene).is_absolute());
    ASSERT_EQ(r.photos.size(), d.views.size());
    save_scene_record(tmp / "scene.json", r);
    const SceneRecord back = load_scene_record(tmp / "scene.json").value();
    EXPECT_EQ(back.scene, r.scene);
    EXPECT_EQ(back.photos[1].name, r.photos[1].name);
    EXPECT_EQ(back.photos[1].rotation, r.photos[1].rotation);
    EXPECT_NO_THROW(check_scene_matches(back, tmp / "scene.json", d));
    EXPECT_NO_THROW(check_scene_matches(back, tmp / "scene.json", load_dataset(scene, {.downscale = 2})))
        << "-r changes intrinsics, not poses";

    SceneRecord moved = back;
    moved.photos[2].translation[1] += 0.01;
    try {
        check_scene_matches(moved, tmp / "scene.json", d);
        ADD_FAILURE() << "a moved camera was accepted";
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr(r.photos[2].name));
        EXPECT_THAT(e.what(), HasSubstr("not the scene this run was trained on"));
    }
    SceneRecord others = back;
    for (RecordedPhoto& p : others.photos) p.name = "other_" + p.name, p.translation[0] += 5;
    EXPECT_NO_THROW(check_scene_matches(others, tmp / "scene.json", d))
        << "no photo in common: nothing to compare";

    EXPECT_FALSE(load_scene_record(tmp / "none.json").has_value());
    std::ofstream(tmp / "bad.json") << "{\"scene\": 3}";
    EXPECT_THROW((void)load_scene_record(tmp / "bad.json"), Error);
}

TEST(CliSceneRecord, EvalAndRenderFindTheSceneAndRefuseAnother) {
    TempDir tmp("cli_scene_record");
    const std::string scene = tmp / "scene", run = tmp / "run";
    CommandResult r = run_lumigauss("synth --preset tiny -o " + shell_quoted(scene), tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_lumigauss(
        "train " + shell_quoted(scene) + " -o " + shell_quoted(run) + " --preset fast --iterations 20 -q",
        tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_TRUE(fs::exists(run_paths(run).scene));

    r = run_lumigauss("eval " + shell_quoted(run) + " -o " + shell_quoted(tmp / "eval") + " -q --no-sheets",
                      tmp);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("eval-summary:"));
    std::string sh;
    for (const auto& e : fs::directory_iterator(scene + "/env"))
        if (e.path().string().ends_with("_sh.txt")) sh = e.path().string();
    ASSERT_FALSE(sh.empty());
    r = run_lumigauss("render " + shell_quoted(run) + " --light " + shell_quoted(sh) + " --cameras test -o " +
                          shell_quoted(tmp / "relit"),
                      tmp);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_FALSE(fs::is_empty(tmp / "relit"));

    const std::string other = tmp / "other";
    fs::copy(scene, other, fs::copy_options::recursive);
    move_first_camera(other);
    r = run_lumigauss("eval " + shell_quoted(run) + " --scene " + shell_quoted(other) + " -o " +
                          shell_quoted(tmp / "eval2") + " -q --no-sheets",
                      tmp);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("not the scene this run was trained on"));
    EXPECT_FALSE(fs::exists(tmp / "eval2/metrics.json"));

    fs::rename(scene, tmp / "moved_away");
    r = run_lumigauss("eval " + shell_quoted(run) + " -o " + shell_quoted(tmp / "eval3") + " -q", tmp);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("no longer there; give --scene"));
}

// train --test-every / --no-test override the scene's split; the run records it, and eval scores the photos
// this run held out (not those of the scene's split file).
TEST(CliSceneRecord, SplitControlIsRecordedAndFollowedByEval) {
    TempDir tmp("cli_split_control");
    const std::string scene = tmp / "scene", run = tmp / "run", all = tmp / "all";
    CommandResult r = run_lumigauss("synth --preset tiny -o " + shell_quoted(scene), tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Dataset d = load_dataset(scene);
    r = run_lumigauss("train " + shell_quoted(scene) + " -o " + shell_quoted(run) +
                          " --preset fast --iterations 10 --test-every 2",
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::size_t held_out = (d.views.size() + 1) / 2;
    EXPECT_THAT(r.output, HasSubstr(std::to_string(d.views.size() - held_out) + " photos (" +
                                    std::to_string(held_out) + " more held out for testing)"));
    const SceneRecord record = load_scene_record(run_paths(run).scene).value();
    std::size_t recorded_test = 0;
    for (const RecordedPhoto& p : record.photos) recorded_test += p.split == "test";
    EXPECT_EQ(recorded_test, held_out);

    r = run_lumigauss("eval " + shell_quoted(run) + " -o " + shell_quoted(tmp / "eval") + " --no-sheets",
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto metrics = nlohmann::json::parse(read_all(tmp / "eval/metrics.json"));
    EXPECT_EQ(metrics["images"].size(), held_out) << "eval scored the scene's split, not the run's";

    r = run_lumigauss("train " + shell_quoted(scene) + " -o " + shell_quoted(run) + " --resume --no-test",
                      tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("saved config and split"));

    r = run_lumigauss("train " + shell_quoted(scene) + " -o " + shell_quoted(all) +
                          " --preset fast --iterations 10 --no-test -q",
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_lumigauss("eval " + shell_quoted(all) + " -o " + shell_quoted(tmp / "eval_all") + " -q", tmp);
    EXPECT_NE(r.exit_code, 0) << "a run that trained on every photo has nothing to test on";
    EXPECT_THAT(r.output, HasSubstr("no test image"));
}

}  // namespace
}  // namespace lumigauss
