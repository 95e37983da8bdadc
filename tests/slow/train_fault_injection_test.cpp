// Fault injection for training: `lumigauss train` killed with SIGKILL at random moments (the checkpoint
// being written included), resumed each time, must end with the same bytes as a run that was never
// interrupted. Slow tier: a dozen short trainings.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
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
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(wait_exit_code(start_training(scene, reference, false)), 0);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    int killed_while_running = 0;
    std::mt19937 random(2026);
    std::uniform_real_distribution<double> moment(0.05, 0.95);
    for (int trial = 0; trial < 4; ++trial) {
        const std::string run = (dir.path() / ("run" + std::to_string(trial))).string();
        int kills = 0;
        for (int attempt = 0; attempt < 3; ++attempt) {  // killed up to three times, resumed after each
            const bool resume = fs::exists(run + "/checkpoint.lgck");
            const pid_t pid = start_training(scene, run, resume);
            std::this_thread::sleep_for(std::chrono::duration<double>(moment(random) * seconds));
            ::kill(pid, SIGKILL);
            int status = 0;
            waitpid(pid, &status, 0);
            if (WIFSIGNALED(status)) ++kills;  // not finished before the kill
        }
        const bool resume = fs::exists(run + "/checkpoint.lgck");
        ASSERT_EQ(wait_exit_code(start_training(scene, run, resume)), 0) << "trial " << trial;
        for (const char* file : {"model.ply", "lighting.lgmlp", "appearance.json", "checkpoint.lgck"})
            EXPECT_EQ(synth_test::read_bytes(run + "/" + file),
                      synth_test::read_bytes(reference + "/" + file))
                << "trial " << trial << " (" << kills << " kills): " << file << " differs";
        killed_while_running += kills;
    }
    EXPECT_GE(killed_while_running, 3) << "too few kills landed while training ran to test anything";
}

}  // namespace
}  // namespace lumigauss
