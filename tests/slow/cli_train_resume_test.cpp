// `lumigauss train --stop-after` then `--resume` reproduces the straight run byte for byte (two 60-iteration
// runs through all three stages). Slow tier: run in the release tree by scripts/test.sh (and CI); under the
// sanitizers CliTrainSignal.InterruptCheckpointsAndResumeFinishes resumes a CLI run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "fast/cli_train_test_util.h"
#include "lumigauss/train/checkpoint.h"

namespace lumigauss {
namespace {

using namespace cli_train_test;
using testing::CommandResult;
using ::testing::HasSubstr;
using testing::run_lumigauss;

// ---- 8. --stop-after then --resume is the straight run ----------------------------------------------------

TEST(CliTrain, StopAfterThenResumeIsByteIdentical) {
    TempDir tmp("cli_train_resume");
    const std::string straight = tmp / "straight", split = tmp / "split";
    const CommandResult a = run_lumigauss(train_args(straight), tmp);
    ASSERT_EQ(a.exit_code, 0) << a.output;

    const CommandResult b = run_lumigauss(train_args(split, kSchedule + " --stop-after 25"), tmp);
    ASSERT_EQ(b.exit_code, 0) << b.output;
    EXPECT_THAT(b.output, HasSubstr("--resume"));
    EXPECT_EQ(load_checkpoint(split + "/checkpoint.lgck").iteration, 25);
    // As after a crash between a log line and the next checkpoint: lines past the checkpoint are dropped
    // on resume.
    {
        std::ofstream log(split + "/log.jsonl", std::ios::app);
        log << R"({"iteration":30,"stage":2,"total":123})" << '\n';
    }
    const CommandResult c = run_lumigauss(
        "train " + shell_quoted(tiny_scene()) + " -o " + shell_quoted(split) + " --resume -q", tmp);
    ASSERT_EQ(c.exit_code, 0) << c.output;
    EXPECT_THAT(c.output, HasSubstr("resuming"));

    // Every file but the log (which holds timings): model, lighting, checkpoint, photos, config, previews.
    auto files_a = folder_bytes(straight), files_b = folder_bytes(split);
    for (const std::string& f : kRunFiles) EXPECT_EQ(files_b.count(f), 1u) << f;
    // Not the run's state: the log and progress.html hold timings, and progress/ holds a picture per
    // checkpoint, so the stopped run has one more.
    for (auto* files : {&files_a, &files_b})
        std::erase_if(*files, [](const auto& f) {
            return f.first == "log.jsonl" || f.first == "progress.html" || f.first.starts_with("progress/");
        });
    EXPECT_EQ(files_a.size(), files_b.size());
    for (const auto& [name, bytes] : files_a)
        EXPECT_TRUE(files_b.count(name) == 1 && files_b.at(name) == bytes)
            << name << " differs between the straight and the resumed run";

    std::vector<nlohmann::json> log_a = read_log(straight + "/log.jsonl");
    std::vector<nlohmann::json> log_b = read_log(split + "/log.jsonl");
    const std::vector<std::int64_t> its = log_iterations(log_b);
    EXPECT_EQ(std::set<std::int64_t>(its.begin(), its.end()).size(), its.size()) << "duplicated iterations";
    EXPECT_EQ(its, log_iterations(log_a));
    ASSERT_EQ(log_a.size(), log_b.size());
    // The held-out photos are scored every 20 iterations of the shadowed stage (40; not 20, before it) and at
    // the end (60), the same before and after the resume.
    std::vector<std::int64_t> scored;
    for (const auto& j : log_b)
        if (j.contains("held_out_psnr")) scored.push_back(j["iteration"]);
    EXPECT_EQ(scored, (std::vector<std::int64_t>{40, 60}));
    for (std::size_t i = 0; i < log_a.size(); ++i) {
        for (auto* line : {&log_a[i], &log_b[i]}) line->erase("elapsed_s"), line->erase("held_out_s");
        EXPECT_EQ(log_a[i], log_b[i]);
    }
}

}  // namespace
}  // namespace lumigauss
