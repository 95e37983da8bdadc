#pragma once
// The tiny synthetic scene (`lumigauss synth --preset tiny`) and a 30-iteration `fast` training run on it,
// made once per build of the `lumigauss` binary and shared by every test process that asks for it: ctest runs
// each test in a process of its own, and the CLI tests of eval, export, render and the holdout protocol all
// need a finished run. The first process makes it in the build folder (LUMIGAUSS_TEST_CACHE_DIR) under a
// file lock; the others wait for the lock and reuse what it made. A rebuilt binary makes a new one. Tests
// must treat the scene and the run as read-only (copy them to change anything).
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <system_error>

#include "support/run_cli.h"
#include "support/temp_dir.h"

namespace lumigauss::testing {

struct SharedTinyRun {
    std::string scene, run;
    int exit_code = -1;  // 0 when both the scene and the run were made
    std::string output;  // what making them printed
};

namespace shared_tiny_run_detail {

// Held while it lives: an exclusive lock on `path` (made if missing).
class FileLock {
  public:
    explicit FileLock(const std::string& path) : fd_(::open(path.c_str(), O_CREAT | O_RDWR, 0644)) {
        if (fd_ >= 0) ::flock(fd_, LOCK_EX);
    }
    ~FileLock() {
        if (fd_ >= 0) ::close(fd_);  // closing releases the lock
    }
    FileLock(const FileLock&) = delete;
    FileLock& operator=(const FileLock&) = delete;

  private:
    int fd_;
};

inline constexpr const char* kSceneArgs = "synth --preset tiny -o ";
inline constexpr const char* kTrainArgs = " --preset fast --iterations 30 -q";

// Names what the run is made from: the recipe and the binary that makes it (size and modification time).
inline std::string recipe_key() {
    std::error_code ec;
    const auto size = std::filesystem::file_size(LUMIGAUSS_BINARY, ec);
    const auto time = std::filesystem::last_write_time(LUMIGAUSS_BINARY, ec).time_since_epoch().count();
    const std::string recipe =
        std::string(kSceneArgs) + kTrainArgs + "|" + std::to_string(size) + "|" + std::to_string(time);
    return std::to_string(std::hash<std::string>{}(recipe));
}

inline SharedTinyRun make() {
    namespace fs = std::filesystem;
    const fs::path cache = LUMIGAUSS_TEST_CACHE_DIR;
    fs::create_directories(cache);
    const fs::path dir = cache / ("tiny_run-" + recipe_key());
    SharedTinyRun made{(dir / "scene").string(), (dir / "run").string(), -1, {}};
    const FileLock lock((cache / "tiny_run.lock").string());
    const fs::path record = dir / "made.txt";  // exit code, then the output; written last
    if (std::ifstream in(record); in) {
        in >> made.exit_code;
        std::ostringstream rest;
        rest << in.rdbuf();
        made.output = rest.str();
        return made;
    }
    std::error_code ec;
    for (const fs::directory_entry& e : fs::directory_iterator(cache, ec))  // runs of older binaries
        if (e.path().filename().string().starts_with("tiny_run-")) fs::remove_all(e.path(), ec);
    fs::create_directories(dir);
    const TempDir tmp("shared_tiny_run");
    CommandResult r = run_lumigauss(kSceneArgs + shell_quoted(made.scene), tmp);
    made.output = r.output;
    if (r.exit_code == 0) {
        r = run_lumigauss("train " + shell_quoted(made.scene) + " -o " + shell_quoted(made.run) + kTrainArgs,
                          tmp);
        made.output += r.output;
    }
    made.exit_code = r.exit_code;
    std::ofstream((record.string() + ".part").c_str()) << made.exit_code << "\n" << made.output;
    fs::rename(record.string() + ".part", record, ec);
    return made;
}

}  // namespace shared_tiny_run_detail

inline const SharedTinyRun& shared_tiny_run() {
    static const SharedTinyRun made = shared_tiny_run_detail::make();
    return made;
}

}  // namespace lumigauss::testing
