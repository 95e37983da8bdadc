#pragma once
// What the `lumigauss train` tests of both tiers share: the tiny scene (generated once per test process), a
// 60-iteration schedule through all three stages, the run's files, and readers of the log and of a run
// folder.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fast/synth_test_util.h"
#include "support/run_cli.h"

namespace lumigauss::cli_train_test {

using synth_test::TempDir;
using testing::shell_quoted;
namespace fs = std::filesystem;

// The tiny scene, generated once per test process.
inline const std::string& tiny_scene() {
    static TempDir dir("cli_train_scene");
    static const std::string root = [] {
        synth::generate_synthetic_scene(synth_test::tiny_options(dir.str()));
        return dir.str();
    }();
    return root;
}

// A 60-iteration run through all three stages: stage 1 to 29, stage 2 30..35, stage 3 from 36;
// densification at 20 and 40 (30 is in stage 2), an opacity reset at 40; a log line every 5 iterations;
// checkpoints and held-out scores every 20.
inline const std::string kSchedule =
    " --preset paper-fast --iterations 60 --set warmup=30 --set start_shadowed=35 --set densify_from=10"
    " --set densify_until=50 --set densify_interval=10 --set opacity_reset_interval=40"
    " --set start_regularization=20 --set lr_position_max_steps=50 --set log_interval=5"
    " --set checkpoint_interval=20 --set held_out_interval=20 -q";

inline std::string train_args(const std::string& run, const std::string& extra = kSchedule) {
    return "train " + shell_quoted(tiny_scene()) + " -o " + shell_quoted(run) + extra;
}

inline const std::vector<std::string> kRunFiles = {"config.json", "log.jsonl",      "checkpoint.lgck",
                                                   "model.ply",   "lighting.lgmlp", "appearance.json"};

inline std::vector<nlohmann::json> read_log(const std::string& path) {
    std::ifstream in(path);
    std::vector<nlohmann::json> lines;
    std::string line;
    while (std::getline(in, line)) {
        nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
        EXPECT_FALSE(j.is_discarded()) << "not JSON: " << line;
        EXPECT_TRUE(j.is_object()) << line;
        lines.push_back(std::move(j));
    }
    return lines;
}

inline std::vector<std::int64_t> log_iterations(const std::vector<nlohmann::json>& log) {
    std::vector<std::int64_t> its;
    for (const auto& j : log) its.push_back(j.value("iteration", std::int64_t(-1)));
    return its;
}

// Every file under a folder (relative path) with its bytes.
inline std::map<std::string, std::string> folder_bytes(const std::string& dir) {
    std::map<std::string, std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file())
            files[fs::relative(e.path(), dir).string()] = synth_test::read_bytes(e.path().string());
    return files;
}

}  // namespace lumigauss::cli_train_test
