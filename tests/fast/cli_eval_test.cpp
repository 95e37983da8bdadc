// `lumigauss eval`: on a short training run of the tiny synthetic scene it writes metrics.json (every key),
// report.md and one contact sheet per test image; a run folder without model.ply and a scene without
// meta.json fail with a message naming the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "support/run_cli.h"
#include "support/shared_tiny_run.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using testing::CommandResult;
using ::testing::HasSubstr;
using testing::run_lumigauss;
using testing::shell_quoted;
namespace fs = std::filesystem;

// The tiny scene and a short run on it, shared with the other CLI tests (support/shared_tiny_run.h).
const testing::SharedTinyRun& tiny_run() {
    return testing::shared_tiny_run();
}

TEST(CliEval, WritesMetricsReportAndContactSheets) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_eval_report");
    const std::string report = tmp / "report";
    const CommandResult r =
        run_lumigauss("eval " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) +
                          " --protocol gt-env -o " + shell_quoted(report),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("light scale"));
    EXPECT_THAT(r.output, HasSubstr("metrics.json"));

    const nlohmann::json j = synth_test::read_json(report + "/metrics.json");
    EXPECT_EQ(j["protocol"], "gt-env");
    EXPECT_EQ(j["downscale"], 1);
    EXPECT_TRUE(j["light_scale"]["value"].is_number());
    EXPECT_EQ(j["light_scale"]["train_photos"], 8);  // the tiny preset's training photos
    EXPECT_TRUE(j["albedo_scale"]["linear"].is_array());
    const Dataset scene = load_dataset(t.scene);
    const auto tests = scene.split(Split::Test);
    ASSERT_EQ(j["images"].size(), tests.size());
    for (std::size_t i = 0; i < tests.size(); ++i) {
        const nlohmann::json& im = j["images"][i];
        EXPECT_EQ(im["name"], tests[i]->name);
        for (const char* mode : {"shadowed", "unshadowed"})
            for (const char* key : {"psnr", "ssim", "mse", "mae"})
                EXPECT_TRUE(im[mode][key].is_number()) << mode << "." << key << " in " << im.dump();
        for (const char* key : {"psnr", "mse", "mae"}) {
            EXPECT_TRUE(im["albedo"][key].is_number()) << key;
            EXPECT_TRUE(im["albedo_gamma"][key].is_number()) << key;
        }
        EXPECT_TRUE(im["normal"]["mean_deg"].is_number());
        EXPECT_TRUE(im["normal"]["median_deg"].is_number());
        EXPECT_GT(im["mask_pixels"].get<int>(), 0);
        const double psnr = im["shadowed"]["psnr"];
        EXPECT_GT(psnr, 3.0);
        EXPECT_LE(psnr, 60.0);
        // The contact sheet: two rows of six panels.
        fs::path sheet = fs::path(report) / "sheets" / tests[i]->name;
        sheet.replace_extension(".png");
        ASSERT_TRUE(fs::exists(sheet)) << sheet;
        const ImageInfo info = read_image_info(sheet.string());
        EXPECT_EQ(info.width, 6 * tests[i]->camera.width + 10);
        EXPECT_EQ(info.height, 2 * tests[i]->camera.height + 2);
    }
    for (const char* mode : {"shadowed", "unshadowed", "albedo", "albedo_gamma", "normal"})
        EXPECT_TRUE(j["mean"].contains(mode)) << mode;
    const std::string md = synth_test::read_bytes(report + "/report.md");
    EXPECT_THAT(md, HasSubstr("gt-env"));
    EXPECT_THAT(md, HasSubstr("training"));
    EXPECT_THAT(md, HasSubstr("sheets/" + fs::path(tests[0]->name).stem().string() + ".png"));
}

// The diagnostic on training views scores every training photo, and says so in metrics.json.
TEST(CliEval, TrainViewsDiagnostic) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_eval_train_views");
    const std::string report = tmp / "report";
    const CommandResult r =
        run_lumigauss("eval " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) +
                          " --cameras train --no-sheets -o " + shell_quoted(report),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json j = synth_test::read_json(report + "/metrics.json");
    EXPECT_EQ(j["views"], "train");
    const nlohmann::json appearance = synth_test::read_json(t.run + "/appearance.json");
    EXPECT_EQ(j["images"].size(), appearance["images"].size());
    // The light scale is fitted on the same (training) photos here.
    EXPECT_EQ(j["light_scale"]["train_photos"], appearance["images"].size());
}

// A bare relightable PLY (e.g. from the official code) is evaluated too: it has no learned lights, so the
// light scale is 1 and the scores are those of the run's surfels under the true lights.
TEST(CliEval, BarePlyIsEvaluatedWithLightScaleOne) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_eval_bare_ply");
    const std::string ply = tmp / "bare.ply";
    fs::copy_file(t.run + "/model.ply", ply);
    const CommandResult r =
        run_lumigauss("eval " + shell_quoted(ply) + " --scene " + shell_quoted(t.scene) +
                          " --protocol gt-env --no-sheets -o " + shell_quoted(tmp / "report"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("light scale k = 1 (a bare PLY"));
    const nlohmann::json m = synth_test::read_json(tmp / "report/metrics.json");
    EXPECT_EQ(m["light_scale"]["value"].get<double>(), 1.0);
    // No learned lights, so nothing to say about their direction (not a misleading 0).
    EXPECT_THAT(r.output, HasSubstr("light_direction=nan"));
}

TEST(CliEval, MissingModelIsNamed) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_eval_no_model");
    const std::string run = tmp / "run";
    fs::create_directories(run);
    for (const char* f : {"config.json", "lighting.lgmlp", "appearance.json"})
        fs::copy_file(t.run + "/" + f, run + "/" + f);
    const CommandResult r = run_lumigauss("eval " + shell_quoted(run) + " --scene " + shell_quoted(t.scene) +
                                              " -o " + shell_quoted(tmp / "report"),
                                          tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr(run + "/model.ply"));
    EXPECT_FALSE(fs::exists(tmp / "report/metrics.json"));
}

TEST(CliEval, SceneWithoutGroundTruthIsNamed) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_eval_no_meta");
    const CommandResult r =
        run_lumigauss("eval " + shell_quoted(t.run) + " --scene " + shell_quoted(tmp / "nothing") + " -o " +
                          shell_quoted(tmp / "report"),
                      tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr(tmp / "nothing/meta.json"));
    const CommandResult bad = run_lumigauss(
        "eval " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) + " --protocol nerf-osr", tmp);
    EXPECT_NE(bad.exit_code, 0);
}

}  // namespace
}  // namespace lumigauss
