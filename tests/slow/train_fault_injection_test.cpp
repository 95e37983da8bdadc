// Fault injection for training: `lumigauss train` killed with SIGKILL at random moments (the checkpoint
// being written included), resumed each time, must end with the same bytes as a run that was never
// interrupted. Slow tier: a dozen short trainings.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "fast/synth_test_util.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;

// Starts `lumigauss train` on the scene (a new run, or --resume), output discarded; returns its pid.
pid_t start_training(const std::string& scene, const std::string& run, bool resume) {
    const pid_t pid = fork();
    if (pid != 0) return pid;
    ::freopen("/dev/null", "w", stdout);
    ::freopen("/dev/null", "w", stderr);
    if (resume)
        ::execl(LUMIGAUSS_BINARY, LUMIGAUSS_BINARY, "train", scene.c_str(), "-o", run.c_str(), "--resume",
                "-q", "--threads", "1", static_cast<char*>(nullptr));
    else
        ::execl(LUMIGAUSS_BINARY, LUMIGAUSS_BINARY, "train", scene.c_str(), "-o", run.c_str(), "--preset",
                "fast", "--iterations", "150", "--set", "checkpoint_interval=7", "-q", "--threads", "1",
                static_cast<char*>(nullptr));
    _exit(127);
}

// The last iteration the run's log.jsonl reports (0 without one).
std::int64_t logged_iteration(const std::string& run) {
    const std::string log = synth_test::read_bytes(run + "/log.jsonl");
    const std::string key = "\"iteration\":";
    const std::size_t at = log.rfind(key);
    return at == std::string::npos ? 0 : std::atoll(log.c_str() + at + key.size());
}

// Lets the training `pid` run until its log reaches `iteration`, then `extra` longer, and kills it. True when
// the kill landed (the run had not finished). Kill moments follow the run's progress rather than a clock, so
// that a machine whose load changes between the reference run and the trials cannot let every run finish
// first.
bool kill_at_iteration(pid_t pid, const std::string& run, std::int64_t iteration,
                       std::chrono::microseconds extra) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(5);
    int status = 0;
    while (logged_iteration(run) < iteration && std::chrono::steady_clock::now() < give_up) {
        if (waitpid(pid, &status, WNOHANG) == pid) return false;  // finished on its own
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    std::this_thread::sleep_for(extra);
    ::kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    return WIFSIGNALED(status);
}

int wait_exit_code(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(TrainFaultInjection, KilledAtRandomMomentsAndResumedEndsWithTheSameBytes) {
    synth_test::TempDir dir("train_fault_injection");
    const std::string scene = (dir.path() / "scene").string();
    synth::generate_synthetic_scene(synth_test::tiny_options(scene));

    const std::string reference = (dir.path() / "reference").string();
    ASSERT_EQ(wait_exit_code(start_training(scene, reference, false)), 0);

    // Each kill lands at a random iteration after the run's last logged one (the log has a line every 10
    // iterations, the run 150), plus a random few milliseconds, so that it also falls inside checkpoint
    // writes.
    constexpr std::int64_t kLastTarget = 140;
    int killed_while_running = 0;
    std::mt19937 random(2026);
    std::uniform_int_distribution<int> extra_us(0, 20000);
    for (int trial = 0; trial < 4; ++trial) {
        const std::string run = (dir.path() / ("run" + std::to_string(trial))).string();
        int kills = 0;
        for (int attempt = 0; attempt < 3; ++attempt) {  // killed three times, resumed after each
            const bool resume = fs::exists(run + "/checkpoint.lgck");
            const std::int64_t done = resume ? logged_iteration(run) : 0;
            std::uniform_int_distribution<std::int64_t> target(std::min(done + 1, kLastTarget), kLastTarget);
            const pid_t pid = start_training(scene, run, resume);
            if (kill_at_iteration(pid, run, target(random), std::chrono::microseconds(extra_us(random))))
                ++kills;
        }
        const bool resume = fs::exists(run + "/checkpoint.lgck");
        ASSERT_EQ(wait_exit_code(start_training(scene, run, resume)), 0) << "trial " << trial;
        for (const char* file : {"model.ply", "lighting.lgmlp", "appearance.json", "checkpoint.lgck"})
            EXPECT_EQ(synth_test::read_bytes(run + "/" + file),
                      synth_test::read_bytes(reference + "/" + file))
                << "trial " << trial << " (" << kills << " kills): " << file << " differs";
        killed_while_running += kills;
    }
    std::printf("[ measured ] %d of 12 kills landed while training ran\n", killed_while_running);
    EXPECT_GE(killed_while_running, 9) << "too few kills landed while training ran to test anything";
}

}  // namespace
}  // namespace lumigauss
