// `export --format splat` (export/splat_format.h): one splat encoded by hand, byte for byte; the file is 32
// bytes per surfel, sorted by area * alpha.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/splat_format.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;

TEST(ExportSplat, OneSplatKnownBytes) {
    SplatRecord s;
    s.position = {1.0f, -2.0f, 0.5f};
    s.scale = {0.25f, 0.5f, 1e-6f};
    s.colour = {1.0f, 0.5f, 0.0f};
    s.alpha = 0.5f;
    s.rotation = {1.0f, 1.0f, 0.0f, -3.0f};  // |q| = sqrt(11): (0.3015, 0.3015, 0, -0.9045)
    const std::array<std::uint8_t, 32> expected = {
        0x00, 0x00, 0x80, 0x3f,  // 1.0f
        0x00, 0x00, 0x00, 0xc0,  // -2.0f
        0x00, 0x00, 0x00, 0x3f,  // 0.5f
        0x00, 0x00, 0x80, 0x3e,  // 0.25f
        0x00, 0x00, 0x00, 0x3f,  // 0.5f
        0xbd, 0x37, 0x86, 0x35,  // 1e-6f = 0x358637bd
        255,  128,  0,    128,   // r g b: 255, round(127.5) = 128, 0; a: round(127.5) = 128
        167,  167,  128,  12,    // round(0.30151 * 128 + 128) = 167 (166.59), 128, round(12.22) = 12
    };
    EXPECT_EQ(encode_splat(s), expected);

    // Clamping: a component of exactly 1 gives 256 -> 255; colours outside [0, 1] clamp.
    SplatRecord t;
    t.rotation = {-2.0f, 0.0f, 0.0f, 0.0f};
    t.colour = {1.5f, -0.2f, 0.25f};
    t.alpha = 1.0f;
    const auto e = encode_splat(t);
    EXPECT_EQ(e[24], 255);
    EXPECT_EQ(e[25], 0);
    EXPECT_EQ(e[26], 64);  // round(63.75)
    EXPECT_EQ(e[27], 255);
    EXPECT_EQ(e[28], 0);  // -1 * 128 + 128
    EXPECT_EQ(e[29], 128);
}

TEST(ExportSplat, FileIsSortedRecords) {
    TempDir tmp("export_splat_file");
    const Camera cam = lumigauss::testing::test_camera();
    const GaussianModel model = relight_test::random_model(cam, 17, 20);
    ShCoeffs<double> sh = relight_test::bright_sh(3);
    const SurfelSides sides = bake_surfel_sides(model, sh.cast<float>(), BakeShading::Shadowed);
    const std::vector<Vec3d> cameras = {cam.center()};
    const std::vector<float> colours = seen_side_colours(model, sides, cameras);
    const std::vector<SplatRecord> records = splat_records(model, colours);
    ASSERT_EQ(records.size(), model.size());
    for (std::size_t i = 0; i < records.size(); ++i) {
        EXPECT_FLOAT_EQ(records[i].scale[0], std::exp(model.param(ModelParam::Scaling)[2 * i]));
        EXPECT_FLOAT_EQ(records[i].scale[2], 1e-6f);
        EXPECT_FLOAT_EQ(records[i].colour[1], colours[3 * i + 1]);
    }
    const std::string path = tmp / "m.splat";
    write_splat_file(path, records);
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string bytes = ss.str();
    ASSERT_EQ(bytes.size(), 32 * model.size());
    std::vector<SplatRecord> sorted = records;
    std::stable_sort(sorted.begin(), sorted.end(), [](const SplatRecord& a, const SplatRecord& b) {
        return a.scale[0] * a.scale[1] * a.alpha > b.scale[0] * b.scale[1] * b.alpha;
    });
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        const auto e = encode_splat(sorted[i]);
        EXPECT_EQ(0, std::memcmp(e.data(), bytes.data() + 32 * i, 32)) << "splat " << i;
    }
    EXPECT_GE(sorted.front().scale[0] * sorted.front().scale[1] * sorted.front().alpha,
              sorted.back().scale[0] * sorted.back().scale[1] * sorted.back().alpha);
}

}  // namespace
}  // namespace lumigauss
