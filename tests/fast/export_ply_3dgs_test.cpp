// `export --format ply-3dgs` (export/ply_3dgs.h, export/baked_colours.h): the file is a standard 3DGS PLY
// (checked by a strict reader written here: exact header, property list and order, binary little-endian,
// exact byte count), its values are the baked colours / copied geometry, and rendering it back through the
// project's 2DGS path (load_2dgs_ply + colors_for_view + rasterize_forward_cpu) matches
// render_with_environment of the relightable model for surfels whose +normal faces the camera.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/ply_3dgs.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/splat_ply.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/util/error.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;

// The 3DGS property list, written out independently of the exporter.
std::vector<std::string> expected_properties() {
    std::vector<std::string> p = {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
    for (int k = 0; k < 45; ++k) p.push_back("f_rest_" + std::to_string(k));
    for (const char* s : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
        p.push_back(s);
    return p;
}

struct StrictPly {
    std::size_t count = 0;
    std::vector<std::string> names;
    std::vector<float> values;  // row-major count x names
    float at(std::size_t row, const std::string& name) const {
        for (std::size_t k = 0; k < names.size(); ++k)
            if (names[k] == name) return values[row * names.size() + k];
        ADD_FAILURE() << "no property " << name;
        return 0;
    }
};

// A strict reader: "ply", "format binary_little_endian 1.0", comments, exactly one element (vertex) of
// float properties, "end_header", then exactly count * properties * 4 bytes.
StrictPly read_strict_ply(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    EXPECT_TRUE(in.good()) << path;
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string bytes = ss.str();
    StrictPly ply;
    std::size_t pos = 0;
    const auto next_line = [&] {
        const std::size_t end = bytes.find('\n', pos);
        EXPECT_NE(end, std::string::npos);
        std::string line = bytes.substr(pos, end - pos);
        pos = end + 1;
        return line;
    };
    EXPECT_EQ(next_line(), "ply");
    EXPECT_EQ(next_line(), "format binary_little_endian 1.0");
    bool had_element = false;
    for (;;) {
        const std::string line = next_line();
        if (line == "end_header") break;
        if (line.rfind("comment ", 0) == 0) continue;
        if (line.rfind("element ", 0) == 0) {
            EXPECT_FALSE(had_element) << "a second element: " << line;
            had_element = true;
            std::istringstream ls(line.substr(8));
            std::string what;
            ls >> what >> ply.count;
            EXPECT_EQ(what, "vertex");
            continue;
        }
        EXPECT_EQ(line.rfind("property float ", 0), 0u) << line;
        EXPECT_TRUE(had_element) << "property before element: " << line;
        ply.names.push_back(line.substr(15));
        if (pos > bytes.size() || ::testing::Test::HasFailure()) return ply;
    }
    EXPECT_EQ(bytes.size() - pos, ply.count * ply.names.size() * 4) << "body size";
    ply.values.resize(ply.count * ply.names.size());
    for (std::size_t i = 0; i < ply.values.size() && pos + 4 * i + 4 <= bytes.size(); ++i) {
        std::uint32_t u = 0;
        for (int b = 0; b < 4; ++b)
            u |= std::uint32_t(std::uint8_t(bytes[pos + 4 * i + std::size_t(b)])) << (8 * b);
        ply.values[i] = std::bit_cast<float>(u);
    }
    return ply;
}

// A random relightable model whose surfels all show their +normal side to `cam` (tilted by up to ~0.2 rad
// from facing it straight on), so that the bake's side choice is the one a renderer makes.
GaussianModel facing_model(const Camera& cam, std::uint64_t seed, std::size_t count = 80) {
    auto raw = relight_test::random_raw(cam, seed, count);
    std::mt19937_64 rng(seed + 1);
    const Mat3d world_from_cam = transpose(cam.rotation);
    for (std::size_t i = 0; i < count; ++i) {
        // 180 deg about camera x (local +z -> camera -z, towards the camera), perturbed.
        const Vec4<double> qc = normalize_quaternion(Vec4<double>{0.1 * relight_test::uniform(rng), 1.0,
                                                                  0.1 * relight_test::uniform(rng),
                                                                  0.1 * relight_test::uniform(rng)});
        const Vec4<double> q = quaternion_from_rotation(world_from_cam * rotation_from_unit_quaternion(qc));
        const double s = 0.5 + relight_test::uniform(rng, 0.0, 1.0);  // unnormalised on purpose
        for (int k = 0; k < 4; ++k) raw[int(ModelParam::Rotation)][4 * i + std::size_t(k)] = float(s * q[k]);
    }
    return GaussianModel::from_raw(std::move(raw), 1.0);
}

// A moderate environment: colours stay below 1, so the [0, 1] clamp of the bake is inactive.
ShCoeffs<float> moderate_env() {
    ShCoeffs<double> sh = relight_test::bright_sh(11);
    for (int k = 0; k < kShCount; ++k) sh.c[k] = sh.c[k] * (k == 0 ? 0.5 : 0.15);
    return sh.cast<float>();
}

TEST(ExportPly3dgs, StrictHeaderAndValues) {
    TempDir tmp("export_3dgs_strict");
    const Camera cam = lumigauss::testing::test_camera();
    const GaussianModel model = facing_model(cam, 3, 25);
    const std::vector<float> colours = bake_surfel_colours(model, moderate_env(), BakeShading::Shadowed);
    const std::string path = tmp / "model_3dgs.ply";
    write_3dgs_ply(path, model, colours);
    const StrictPly ply = read_strict_ply(path);
    ASSERT_FALSE(::testing::Test::HasFailure());
    EXPECT_EQ(ply.count, model.size());
    EXPECT_EQ(ply.names, expected_properties());
    EXPECT_EQ(ply_3dgs_property_names(), expected_properties());
    const auto& xyz = model.param(ModelParam::Xyz);
    const auto& op = model.param(ModelParam::Opacity);
    const auto& sc = model.param(ModelParam::Scaling);
    for (std::size_t i = 0; i < model.size(); ++i) {
        EXPECT_EQ(ply.at(i, "x"), xyz[3 * i]);
        EXPECT_EQ(ply.at(i, "z"), xyz[3 * i + 2]);
        EXPECT_EQ(ply.at(i, "opacity"), op[i]);
        EXPECT_EQ(ply.at(i, "scale_0"), sc[2 * i]);
        EXPECT_EQ(ply.at(i, "scale_1"), sc[2 * i + 1]);
        EXPECT_NEAR(ply.at(i, "scale_2"), std::log(1e-6), 1e-5);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(0.5 + 0.28209479177387814 * ply.at(i, "f_dc_" + std::to_string(c)),
                        colours[3 * i + std::size_t(c)], 1e-6);
        for (int k = 0; k < 45; ++k) EXPECT_EQ(ply.at(i, "f_rest_" + std::to_string(k)), 0.0f);
        double qn = 0, nn = 0;
        for (int k = 0; k < 4; ++k) qn += std::pow(ply.at(i, "rot_" + std::to_string(k)), 2);
        for (const char* n : {"nx", "ny", "nz"}) nn += std::pow(ply.at(i, n), 2);
        EXPECT_NEAR(qn, 1.0, 1e-5);
        EXPECT_NEAR(nn, 1.0, 1e-5);
        EXPECT_GE(ply.at(i, "rot_0") * model.param(ModelParam::Rotation)[4 * i], 0.0f);  // same sign
    }
}

// Render-back: the exported 3DGS PLY through the 2DGS path equals the relightable render, max abs pixel
// difference <= 1e-5 (float round trips of exp/log, sigmoid/logit and the f_dc encoding).
void expect_render_back(BakeShading bake, ShadingMode mode) {
    TempDir tmp("export_3dgs_render");
    const Camera cam = lumigauss::testing::test_camera(48, 40);
    const GaussianModel model = facing_model(cam, 5);
    const ShCoeffs<float> env = moderate_env();
    const std::vector<float> colours = bake_surfel_colours(model, env, bake);
    float top = 0;
    for (float c : colours) top = std::max(top, c);
    ASSERT_LT(top, 0.999f) << "the environment is too bright for an unclamped comparison";

    // Every surfel shows its positive side.
    ViewNormals normals;
    compute_view_normals(model, cam, normals);
    for (auto side : normals.positive_side) ASSERT_EQ(side, 1);

    const std::string path = tmp / "baked.ply";
    write_3dgs_ply(path, model, colours);
    ViewDependentSurfels loaded = load_2dgs_ply(path);
    ASSERT_EQ(loaded.size(), model.size());
    EXPECT_EQ(loaded.sh_degree, 3);
    colors_for_view(loaded, cam.center());
    RasterState<float> state;
    const RasterImages<float> back =
        rasterize_forward_cpu(cam, loaded.surfels, RasterSettings<float>{}, state);
    const RasterImages<float> ref = render_with_environment(model, cam, env, mode);
    ASSERT_EQ(back.color.size(), ref.color.size());
    double max_diff = 0, sum = 0;
    for (std::size_t p = 0; p < ref.color.size(); ++p) {
        max_diff = std::max(max_diff, double(std::abs(back.color[p] - ref.color[p])));
        sum += ref.color[p];
    }
    EXPECT_GT(sum, 10.0) << "nothing rendered";
    EXPECT_LE(max_diff, 1e-5);
}

TEST(ExportPly3dgs, RenderBackMatchesShadowedRender) {
    expect_render_back(BakeShading::Shadowed, ShadingMode::Shadowed);
}

TEST(ExportPly3dgs, RenderBackMatchesUnshadowedRender) {
    expect_render_back(BakeShading::Unshadowed, ShadingMode::Unshadowed);
}

TEST(ExportPly3dgs, BakeClampsToUnitRangeAndParsesShading) {
    const Camera cam = lumigauss::testing::test_camera();
    const GaussianModel model = facing_model(cam, 9, 30);
    ShCoeffs<float> hot = moderate_env();
    for (int k = 0; k < kShCount; ++k) hot.c[k] = hot.c[k] * 50.0f;
    for (float c : bake_surfel_colours(model, hot, BakeShading::Unshadowed)) {
        EXPECT_GE(c, 0.0f);
        EXPECT_LE(c, 1.0f);
    }
    EXPECT_EQ(parse_bake_shading("shadowed"), BakeShading::Shadowed);
    EXPECT_EQ(parse_bake_shading("unshadowed"), BakeShading::Unshadowed);
    EXPECT_THROW(parse_bake_shading("both"), Error);
}

}  // namespace
}  // namespace lumigauss
