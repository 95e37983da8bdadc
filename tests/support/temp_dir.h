#pragma once
// A fresh folder under the system temp dir, unique per process and object, removed with everything in it.
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>

namespace lumigauss::testing {

class TempDir {
  public:
    // Named after `tag` (for example the test's name) so that a folder left by a crash says where it came
    // from.
    explicit TempDir(const std::string& tag) {
        static std::atomic<int> counter{0};
        path_ = std::filesystem::temp_directory_path() /
                ("lumigauss_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return path_; }
    std::string str() const { return path_.string(); }
    std::string sub(const std::string& rel) const { return (path_ / rel).string(); }
    std::string operator/(const std::string& rel) const { return sub(rel); }

  private:
    std::filesystem::path path_;
};

}  // namespace lumigauss::testing
