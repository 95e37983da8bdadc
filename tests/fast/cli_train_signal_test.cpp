// Ctrl-C during `lumigauss train`: the run stops at the next iteration boundary, writes its checkpoint,
// exits with 130, and --resume continues from there to the end.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "lumigauss/train/checkpoint.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;

std::size_t count_lines(const fs::path& path) {
    std::ifstream in(path);
    std::size_t n = 0;
    for (std::string line; std::getline(in, line);) ++n;
    return n;
}

TEST(CliTrainSignal, InterruptCheckpointsAndResumeFinishes) {
    synth_test::TempDir dir("train_signal");
    synth::generate_synthetic_scene(synth_test::tiny_options((dir.path() / "scene").string()));
    const fs::path run = dir.path() / "run";

    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        // Long enough that it cannot finish before the signal; logs every 10 iterations.
        const std::string scene = (dir.path() / "scene").string(), out = run.string();
        ::freopen("/dev/null", "w", stdout);
        ::execl(LUMIGAUSS_BINARY, LUMIGAUSS_BINARY, "train", scene.c_str(), "-o", out.c_str(), "--preset",
                "fast", "--iterations", "1000000", "--set", "checkpoint_interval=0", "-q", "--threads", "1",
                static_cast<char*>(nullptr));
        _exit(127);
    }
    // Wait until training is under way (a few log lines), then interrupt.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (count_lines(run / "log.jsonl") < 3 && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_GE(count_lines(run / "log.jsonl"), 3u) << "training did not start";
    ASSERT_EQ(kill(pid, SIGINT), 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);

    // The checkpoint holds the state at the iteration it stopped at (no checkpoint_interval: only Ctrl-C
    // wrote it).
    ASSERT_TRUE(fs::exists(run / "checkpoint.lgck"));
    const TrainState state = load_checkpoint((run / "checkpoint.lgck").string());
    EXPECT_GE(state.iteration, 30);
    EXPECT_LT(state.iteration, 1000000);
    EXPECT_TRUE(fs::exists(run / "model.ply"));  // the snapshot written with the checkpoint: openable now

    // Resume to a near end: finishes and writes the model.
    const std::string resume = std::string(LUMIGAUSS_BINARY) + " train " + (dir.path() / "scene").string() +
                               " -o " + run.string() + " --resume -q --iterations " +
                               std::to_string(state.iteration + 5) + " > " +
                               (dir.path() / "log.txt").string() + " 2>&1";
    ASSERT_EQ(std::system(resume.c_str()), 0) << synth_test::read_bytes((dir.path() / "log.txt").string());
    EXPECT_TRUE(fs::exists(run / "model.ply"));
    EXPECT_EQ(load_checkpoint((run / "checkpoint.lgck").string()).iteration, state.iteration + 5);
}

}  // namespace
}  // namespace lumigauss
