// `lumigauss train`: a short run on the tiny synthetic scene writes every run file, the held-out scores are
// the holdout protocol's, an existing run is protected unless --resume or --force is given, and bad input
// fails with a message naming the file or key. --stop-after then --resume:
// tests/slow/cli_train_resume_test.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_train_test_util.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/train/checkpoint.h"
#include "lumigauss/train/run_folder.h"
#include "support/run_cli.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using testing::CommandResult;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::run_lumigauss;
using testing::shell_quoted;
namespace fs = std::filesystem;

using namespace cli_train_test;

// ---- 7. A run writes every file ----------------------------------------------------------------------

TEST(CliTrain, ShortRunWritesEveryRunFile) {
    TempDir tmp("cli_train_files");
    const std::string run = tmp / "run";
    const CommandResult r = run_lumigauss(train_args(run), tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const std::string& f : kRunFiles) EXPECT_TRUE(fs::exists(run + "/" + f)) << f << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr("train: done"));

    // config.json: the full config with the overrides.
    const nlohmann::json config = synth_test::read_json(run + "/config.json");
    ASSERT_TRUE(config.is_object());
    EXPECT_EQ(config["preset"], "paper-fast");
    EXPECT_EQ(config["iterations"], 60);
    EXPECT_EQ(config["warmup"], 30);
    EXPECT_EQ(config["start_shadowed"], 35);
    EXPECT_EQ(config["densify_from"], 10);
    EXPECT_EQ(config["densify_until"], 50);
    EXPECT_EQ(config["densify_interval"], 10);
    EXPECT_EQ(config["opacity_reset_interval"], 40);
    EXPECT_EQ(config["start_regularization"], 20);
    EXPECT_EQ(config["lr_position_max_steps"], 50);
    EXPECT_EQ(config["log_interval"], 5);
    EXPECT_EQ(config["lambda_shadow"], 10.0);  // a preset value kept
    TrainConfig parsed = train_preset("paper");
    apply_train_config_json(parsed, synth_test::read_bytes(run + "/config.json"), "config.json");
    EXPECT_EQ(parsed.warmup, 30);
    EXPECT_EQ(parsed.preset, "paper-fast");

    // log.jsonl: one object per logged iteration, every loss key, in order.
    const std::vector<nlohmann::json> log = read_log(run + "/log.jsonl");
    ASSERT_FALSE(log.empty());
    for (const auto& j : log)
        for (const char* key : {"iteration", "stage", "total", "l1_shadowed", "dssim_shadowed",
                                "l1_unshadowed", "dssim_unshadowed", "range01", "consistency", "shadow",
                                "env", "normal", "distortion", "psnr", "surfels"})
            EXPECT_TRUE(j.contains(key)) << key << " missing in " << j.dump();
    const std::vector<std::int64_t> its = log_iterations(log);
    std::vector<std::int64_t> expected;
    for (std::int64_t i = 5; i <= 60; i += 5) expected.push_back(i);
    EXPECT_EQ(its, expected);  // densification at 20 and 40 falls on logged iterations
    std::set<int> stages;
    for (const auto& j : log) {
        const std::int64_t it = j["iteration"];
        const int stage = j["stage"];
        stages.insert(stage);
        EXPECT_EQ(stage, it < 30 ? 1 : it <= 35 ? 2 : 3) << it;
        // No photo is rendered while the transfer is fitted: PSNR 0 there drew a fake dip in plots.
        EXPECT_EQ(j["psnr"].is_null(), stage == 2) << it;
        EXPECT_EQ(j.contains("cloned"), it == 20 || it == 40) << it;
    }
    EXPECT_EQ(stages, (std::set<int>{1, 2, 3}));

    // The model files load and agree with the log and the scene.
    const Dataset scene = load_dataset(tiny_scene());
    std::vector<std::string> train_names;
    for (const View* v : scene.split(Split::Train)) train_names.push_back(v->name);
    EXPECT_EQ(load_appearance(run + "/appearance.json"), train_names);
    const SurfelModel model = load_relightable_ply(run + "/model.ply");
    EXPECT_EQ(model.size(), log.back()["surfels"].get<std::size_t>());
    EXPECT_GT(model.size(), 0u);
    EXPECT_EQ(load_lighting_mlp(run + "/lighting.lgmlp").num_images(), int(train_names.size()));
    const TrainState state = load_checkpoint(run + "/checkpoint.lgck");
    EXPECT_EQ(state.iteration, 60);
    EXPECT_EQ(state.model.size(), model.size());
    EXPECT_EQ(state.image_names, train_names);
}

// The held-out photos are scored as `eval --protocol holdout --fit-iterations 100` scores them: the last log
// line holds what eval reports for the finished model, and the end of the output says it. Without held-out
// photos (--no-test) nothing is scored.
TEST(CliTrain, HeldOutScoresAreTheHoldoutProtocols) {
    TempDir tmp("cli_train_held_out");
    const std::string run = tmp / "run";
    const CommandResult r = run_lumigauss(train_args(run, " --preset fast --iterations 20"), tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("2 held-out photos: PSNR"));
    const std::vector<nlohmann::json> log = read_log(run + "/log.jsonl");
    ASSERT_FALSE(log.empty());
    ASSERT_TRUE(log.back().contains("held_out_psnr")) << log.back().dump();
    const CommandResult e =
        run_lumigauss("eval " + shell_quoted(run) + " --protocol holdout --fit-iterations 100 -o " +
                          shell_quoted(tmp / "eval") + " -q",
                      tmp);
    ASSERT_EQ(e.exit_code, 0) << e.output;
    const std::size_t at = e.output.find("eval-summary: shadowed_psnr=");
    ASSERT_NE(at, std::string::npos) << e.output;
    const double eval_psnr =
        std::stod(e.output.substr(at + std::string("eval-summary: shadowed_psnr=").size()));
    EXPECT_NEAR(log.back()["held_out_psnr"].get<double>(), eval_psnr, 1e-4);

    const std::string all = tmp / "all";
    const CommandResult n = run_lumigauss(train_args(all, " --preset fast --iterations 20 --no-test"), tmp);
    ASSERT_EQ(n.exit_code, 0) << n.output;
    EXPECT_THAT(n.output, Not(HasSubstr("held-out photos")));
    for (const nlohmann::json& j : read_log(all + "/log.jsonl")) EXPECT_FALSE(j.contains("held_out_psnr"));
}

// ---- 9. An existing run is protected ---------------------------------------------------------------------

TEST(CliTrain, ExistingRunNeedsResumeOrForce) {
    TempDir tmp("cli_train_exists");
    const std::string run = tmp / "run";
    const std::string short_run = " --preset fast --iterations 20 --set log_interval=5 -q";
    ASSERT_EQ(run_lumigauss(train_args(run, short_run), tmp).exit_code, 0);
    const auto before = folder_bytes(run);
    for (const std::string& f : kRunFiles) ASSERT_EQ(before.count(f), 1u) << f;

    const CommandResult again = run_lumigauss(train_args(run, short_run), tmp);
    EXPECT_NE(again.exit_code, 0);
    EXPECT_THAT(again.output, HasSubstr("--resume"));
    EXPECT_THAT(again.output, HasSubstr("--force"));
    EXPECT_THAT(again.output, HasSubstr("checkpoint.lgck"));
    EXPECT_TRUE(folder_bytes(run) == before) << "a refused run changed the folder";

    const CommandResult forced =
        run_lumigauss(train_args(run, " --preset fast --iterations 30 --set log_interval=5 -q --force"), tmp);
    ASSERT_EQ(forced.exit_code, 0) << forced.output;
    EXPECT_EQ(synth_test::read_json(run + "/config.json")["iterations"], 30);
    EXPECT_EQ(load_checkpoint(run + "/checkpoint.lgck").iteration, 30);
    EXPECT_EQ(log_iterations(read_log(run + "/log.jsonl")),
              (std::vector<std::int64_t>{5, 10, 15, 20, 25, 30}));
}

// --iterations scales the preset's schedule (issue #28): a 30-iteration fast run reaches the shadowed stage
// and says so; a --set stage boundary past the end is kept and warned about.
TEST(CliTrain, IterationsScaleTheScheduleAndAShortStageIsWarnedAbout) {
    TempDir tmp("cli_train_schedule");
    const CommandResult scaled = run_lumigauss(train_args(tmp / "a", " --preset fast --iterations 30"), tmp);
    ASSERT_EQ(scaled.exit_code, 0) << scaled.output;
    EXPECT_THAT(scaled.output, HasSubstr("stages: unshadowed 1-14, transfer fitting 15-16, shadowed 17-30"));
    EXPECT_THAT(scaled.output, ::testing::Not(HasSubstr("warning")));
    EXPECT_EQ(synth_test::read_json(tmp / "a/config.json")["start_shadowed"], 16);
    const CommandResult kept =
        run_lumigauss(train_args(tmp / "b", " --preset fast --iterations 30 --set start_shadowed=40"), tmp);
    ASSERT_EQ(kept.exit_code, 0) << kept.output;
    EXPECT_THAT(kept.output,
                HasSubstr("warning: the run ends at iteration 30, before the shadowed stage (41)"));
}

// --backend: the rasterizer's backend. auto trains on the CPU where there is no GPU, bit for bit as the
// default; cuda without the CUDA backend is refused before anything is read or written, saying why.
TEST(CliTrain, BackendAutoIsTheCpuWithoutAGpuAndCudaIsRefused) {
    if (choose_backend("auto") == RasterBackend::Cuda) GTEST_SKIP() << "this machine has the CUDA backend";
    TempDir tmp("cli_train_backend");
    const std::string short_run = " --preset fast --iterations 12 --set log_interval=4 -q";
    ASSERT_EQ(run_lumigauss(train_args(tmp / "cpu", short_run), tmp).exit_code, 0);
    const CommandResult automatic =
        run_lumigauss(train_args(tmp / "auto", short_run + " --backend auto"), tmp);
    ASSERT_EQ(automatic.exit_code, 0) << automatic.output;
    EXPECT_EQ(synth_test::read_bytes(tmp / "auto/model.ply"), synth_test::read_bytes(tmp / "cpu/model.ply"));

    const CommandResult cuda = run_lumigauss(train_args(tmp / "cuda", short_run + " --backend cuda"), tmp);
    EXPECT_NE(cuda.exit_code, 0);
    EXPECT_THAT(cuda.output, HasSubstr("--backend cuda"));
    EXPECT_THAT(cuda.output, HasSubstr("CUDA"));
    EXPECT_FALSE(std::filesystem::exists(tmp / "cuda")) << "a refused run wrote its folder";
}

// ---- 10. Bad input
// ------------------------------------------------------------------------------------------

TEST(CliTrain, BadInputFailsNamingTheFileOrKey) {
    TempDir tmp("cli_train_bad");
    {
        const std::string missing = tmp / "no_such_scene";
        const CommandResult r = run_lumigauss(
            "train " + shell_quoted(missing) + " -o " + shell_quoted(tmp / "run1") + " -q", tmp);
        EXPECT_NE(r.exit_code, 0);
        EXPECT_THAT(r.output, HasSubstr("no_such_scene"));
        EXPECT_FALSE(fs::exists(tmp / "run1/checkpoint.lgck"));
    }
    {
        const CommandResult r = run_lumigauss(train_args(tmp / "run2", " --set lambda_shadoww=3 -q"), tmp);
        EXPECT_NE(r.exit_code, 0);
        EXPECT_THAT(r.output, HasSubstr("lambda_shadoww"));
        EXPECT_FALSE(fs::exists(tmp / "run2"));
    }
    {
        const std::string bad = tmp / "bad_config.json";
        std::ofstream(bad) << "{ \"iterations\": 10, ";
        const CommandResult r =
            run_lumigauss(train_args(tmp / "run3", " --config " + shell_quoted(bad) + " -q"), tmp);
        EXPECT_NE(r.exit_code, 0);
        EXPECT_THAT(r.output, HasSubstr(bad));
        EXPECT_FALSE(fs::exists(tmp / "run3"));
    }
    {
        const std::string run = tmp / "run4";
        const CommandResult r = run_lumigauss(train_args(run, " --resume -q"), tmp);
        EXPECT_NE(r.exit_code, 0);
        EXPECT_THAT(r.output, HasSubstr(run + "/checkpoint.lgck"));
    }
}

}  // namespace
}  // namespace lumigauss
