// `lumigauss render --ply --scene`: the CLI renders what the library renders, one PNG per view.
#include <gtest/gtest.h>

#include <cstdlib>

#include "io_test_util.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/model/splat_ply.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cuda/rasterizer_cuda.h"

namespace lumigauss {
namespace {

using test::TempDir;

// One grey surfel at the origin, degree 0: a model for tests about which views get rendered.
void save_one_surfel_ply(const std::string& path) {
    ViewDependentSurfels m;
    m.sh_degree = 0;
    m.surfels.resize(1);
    m.sh.assign(3, 0.f);
    m.surfels.quats[0] = 1.f, m.surfels.scales[0] = m.surfels.scales[1] = 0.2f, m.surfels.opacities[0] = 0.8f;
    save_2dgs_ply(path, m);
}

TEST(CliRender, WritesOnePngPerViewMatchingTheLibrary) {
    TempDir dir;
    test::write_scene(dir.path() / "scene", test::small_model(2, 48, 32));
    // Surfels near the origin, in front of both cameras (which look down +z from z = -5).
    ViewDependentSurfels m;
    m.sh_degree = 1;
    const std::size_t n = 40;
    m.surfels.resize(n);
    m.sh.assign(n * 4 * 3, 0.f);
    for (std::size_t i = 0; i < n; ++i) {
        const float a = float(i) * 0.7f;
        m.surfels.means[3 * i] = 1.2f * std::cos(a), m.surfels.means[3 * i + 1] = 0.8f * std::sin(a);
        m.surfels.means[3 * i + 2] = 0.1f * float(i % 5);
        m.surfels.quats[4 * i] = 1.f, m.surfels.quats[4 * i + 1] = 0.1f * float(i % 3);
        m.surfels.scales[2 * i] = 0.2f, m.surfels.scales[2 * i + 1] = 0.1f;
        m.surfels.opacities[i] = 0.8f;
        for (int c = 0; c < 3; ++c) m.sh[i * 12 + c] = 0.5f * std::sin(a + float(c));
        m.sh[i * 12 + 9] = 0.3f;  // some view dependence
    }
    save_2dgs_ply(dir / "model.ply", m);
    const std::string cmd = std::string(LUMIGAUSS_BINARY) + " render --ply " + (dir / "model.ply") +
                            " --scene " + (dir / "scene") + " -o " + (dir / "out") + " --maps > " +
                            (dir / "log.txt") + " 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << test::read_text(dir / "log.txt");

    const Dataset scene = load_dataset(dir / "scene");
    ViewDependentSurfels loaded = load_2dgs_ply(dir / "model.ply");
    for (const View& v : scene.views) {
        colors_for_view(loaded, v.camera.center());
        RasterState<float> st;
        const auto img = rasterize_forward_cpu(v.camera, loaded.surfels, RasterSettings<float>{}, st);
        const std::string stem = v.name.substr(0, v.name.size() - 4);
        const Image png = read_image(dir / ("out/" + stem + ".png"));
        ASSERT_EQ(png.width, 48);
        double max_err = 0, sum = 0;
        for (std::size_t p = 0; p < png.pixels.size(); ++p) {
            max_err = std::max(max_err,
                               std::abs(double(png.pixels[p]) - std::clamp(double(img.color[p]), 0.0, 1.0)));
            sum += png.pixels[p];
        }
        EXPECT_LE(max_err, 0.5 / 255 + 1e-6) << v.name;  // 8-bit rounding only
        EXPECT_GT(sum, 10.0) << "the surfels should be visible in " << v.name;
        EXPECT_TRUE(std::filesystem::exists(dir / ("out/" + stem + "_depth.exr")));
    }
}

// --cameras names a PLY's views as it names a run's (--split is the old spelling); orbits are for runs.
TEST(CliRender, CamerasChooseThePlyViews) {
    TempDir dir;
    test::write_scene(dir.path() / "scene", test::small_model(2, 24, 16));
    save_one_surfel_ply(dir / "model.ply");
    const Dataset scene = load_dataset(dir / "scene");
    const auto pngs = [](const std::filesystem::path& folder) {
        std::size_t count = 0;
        for (const auto& e : std::filesystem::directory_iterator(folder))
            count += e.path().extension() == ".png";
        return count;
    };
    const std::string base = std::string(LUMIGAUSS_BINARY) + " render --ply " + (dir / "model.ply") +
                             " --scene " + (dir / "scene") + " -o ";
    for (const char* option : {"--cameras", "--split"}) {
        const std::string out = dir / (std::string("out") + option);
        const std::string cmd = base + out + " " + option + " test > " + (dir / "log.txt") + " 2>&1";
        ASSERT_EQ(std::system(cmd.c_str()), 0) << test::read_text(dir / "log.txt");
        EXPECT_EQ(pngs(out), scene.split(Split::Test).size()) << option;
        EXPECT_LT(pngs(out), scene.views.size());
    }
    const std::string orbit = base + (dir / "orbit") + " --cameras orbit > " + (dir / "log.txt") + " 2>&1";
    EXPECT_NE(std::system(orbit.c_str()), 0);
    EXPECT_NE(test::read_text(dir / "log.txt").find("--cameras 'orbit'"), std::string::npos)
        << test::read_text(dir / "log.txt");
}

TEST(CliRender, BadModelGivesAnErrorNamingTheFile) {
    TempDir dir;
    test::write_scene(dir.path() / "scene", test::small_model(1, 16, 16));
    test::write_text(dir / "bad.ply",
                     "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n");
    const std::string cmd = std::string(LUMIGAUSS_BINARY) + " render --ply " + (dir / "bad.ply") +
                            " --scene " + (dir / "scene") + " -o " + (dir / "out") + " > " +
                            (dir / "log.txt") + " 2>&1";
    const int rc = std::system(cmd.c_str());
    EXPECT_NE(rc, 0);
    const std::string log = test::read_text(dir / "log.txt");
    EXPECT_NE(log.find("bad.ply"), std::string::npos) << log;

    // A model with no surfels rendered black images and exited 0.
    test::write_text(dir / "empty.ply",
                     "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
                     "property float z\nend_header\n");
    const std::string empty = std::string(LUMIGAUSS_BINARY) + " render --ply " + (dir / "empty.ply") +
                              " --scene " + (dir / "scene") + " -o " + (dir / "out2") + " > " +
                              (dir / "log2.txt") + " 2>&1";
    EXPECT_NE(std::system(empty.c_str()), 0);
    const std::string log2 = test::read_text(dir / "log2.txt");
    EXPECT_NE(log2.find("empty.ply"), std::string::npos) << log2;
    EXPECT_NE(log2.find("no surfels"), std::string::npos) << log2;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out2")) << "a refused model wrote a folder";
}

// Without the CUDA backend (CI) `--backend cuda` is refused with the reason, and nothing is written; with it,
// the GPU's images are the CPU's (bench/cuda_device_check.sh compares the two backends' PNGs on a GPU).
TEST(CliRender, CudaBackendWithoutGpuSaysWhy) {
    if (cuda_backend_available()) GTEST_SKIP() << "a GPU is usable here";
    TempDir dir;
    test::write_scene(dir.path() / "scene", test::small_model(1, 16, 16));
    save_one_surfel_ply(dir / "model.ply");
    const std::string cmd = std::string(LUMIGAUSS_BINARY) + " render --ply " + (dir / "model.ply") +
                            " --scene " + (dir / "scene") + " -o " + (dir / "out") + " --backend cuda > " +
                            (dir / "log.txt") + " 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0);
    const std::string log = test::read_text(dir / "log.txt");
    EXPECT_NE(log.find("CUDA"), std::string::npos) << log;
    EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace lumigauss
