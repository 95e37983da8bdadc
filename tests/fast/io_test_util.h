#pragma once
// Helpers for the io tests: a self-deleting temporary folder and small synthetic COLMAP scenes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>

#include "lumigauss/io/colmap.h"
#include "lumigauss/io/image.h"
#include "lumigauss/util/error.h"
#include "support/temp_dir.h"

namespace lumigauss::test {

namespace fs = std::filesystem;

// The shared data folder, or "" when this checkout has none (users cloning the repo do not).
inline std::string plaza_dir() {
    const fs::path dir = fs::path(LUMIGAUSS_SHARED_DIR) / "data" / "plaza_mini";
    return fs::is_directory(dir / "sparse" / "0") ? dir.string() : std::string();
}

// A temporary folder named after the running test.
class TempDir : public lumigauss::testing::TempDir {
  public:
    TempDir() : lumigauss::testing::TempDir(current_test_name()) {}

  private:
    static std::string current_test_name() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        return info ? std::string(info->test_suite_name()) + "_" + info->name() : "none";
    }
};

// Runs `f` and expects an Error whose message contains every one of `parts` (typically the file name).
template <typename F>
void expect_error(F f, std::initializer_list<std::string> parts) {
    try {
        f();
        ADD_FAILURE() << "no Error thrown";
    } catch (const Error& e) {
        for (const std::string& p : parts)
            EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
    }
}

inline void write_text(const std::string& path, const std::string& text) {
    fs::create_directories(fs::path(path).parent_path());
    std::ofstream(path, std::ios::binary) << text;
}

inline std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A smooth image with distinct channels, values exact multiples of 1/255.
inline Image test_image(int w, int h, int c) {
    Image im(w, h, c);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < c; ++k) im.at(x, y, k) = float((x * 7 + y * 13 + k * 50) % 256) / 255.0f;
    return im;
}

// `n` PINHOLE cameras (one per image) of w x h, looking down +z from x = 0..n-1, and a few points.
inline ColmapModel small_model(int n, int w, int h) {
    ColmapModel m;
    for (int i = 0; i < n; ++i) {
        m.cameras[i + 1] = ColmapCamera{i + 1, "PINHOLE", w, h, {20.0 + i, 21.0 + i, w / 2.0, h / 2.0}};
        ColmapImage im;
        im.id = i + 1;
        im.name = "img_" + std::to_string(i) + ".png";
        im.qvec = {1, 0, 0, 0};
        im.tvec = {-double(i), 0, 5};
        im.camera_id = i + 1;
        m.images.push_back(im);
    }
    m.point_xyz = {{0, 0, 0}, {1, 2, 3}, {-1, 0.5f, 2}};
    m.point_rgb = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    return m;
}

// A COLMAP scene folder: sparse/0 (text or binary), images/ with PNGs of the cameras' sizes, optional masks/.
inline void write_scene(const fs::path& root, const ColmapModel& m, bool binary = false, bool masks = false) {
    if (binary)
        write_colmap_binary((root / "sparse" / "0").string(), m);
    else
        write_colmap_text((root / "sparse" / "0").string(), m);
    fs::create_directories(root / "images");
    if (masks) fs::create_directories(root / "masks");
    for (const ColmapImage& im : m.images) {
        const ColmapCamera& c = m.cameras.at(im.camera_id);
        fs::create_directories((root / "images" / im.name).parent_path());
        if (masks) fs::create_directories((root / "masks" / im.name).parent_path());
        write_png((root / "images" / im.name).string(), test_image(c.width, c.height, 3));
        if (masks) write_png((root / "masks" / im.name).string(), Image(c.width, c.height, 1, 1.0f));
    }
}

}  // namespace lumigauss::test
