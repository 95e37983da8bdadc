// `export --format ply-3dgs` (export/ply_3dgs.h, export/two_sided_sh.h, export/baked_colours.h): the file
// is a standard 3DGS PLY (checked by a strict reader written here: exact header, property list and order for
// each SH degree, binary little-endian, exact byte count), its geometry is the model's, and rendered by this
// file's own 3DGS colour evaluation (the Inria `eval_sh` constants written out here, channel-major f_rest)
// it reproduces the relightable render from cameras on BOTH sides of the surfels: the baked colours of the
// two sides of a two-sided surfel.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "export_test_scene.h"
#include "lumigauss/cameras/orbit.h"
#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/ply_3dgs.h"
#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/export/world_turn.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/util/error.h"
#include "relight_test_util.h"
#include "support/inria_sh.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using namespace lumigauss::export_test;

// The 3DGS property list for an SH degree, written out independently of the exporter.
std::vector<std::string> expected_properties(int degree) {
    std::vector<std::string> p = {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
    const int rest = degree == 0 ? 0 : degree == 1 ? 9 : degree == 2 ? 24 : 45;
    for (int k = 0; k < rest; ++k) p.push_back("f_rest_" + std::to_string(k));
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

// The colour a 3DGS renderer gives vertex `row` seen along the unit direction `d` (camera -> splat), f_rest
// channel-major as the Inria code stores it.
Vec3d inria_colour(const StrictPly& ply, std::size_t row, int degree, Vec3d d) {
    const int per_channel = (degree + 1) * (degree + 1) - 1;
    const double dc[3] = {ply.at(row, "f_dc_0"), ply.at(row, "f_dc_1"), ply.at(row, "f_dc_2")};
    return lumigauss::testing::inria_sh_colour(
        degree, dc,
        [&](int k, int c) { return ply.at(row, "f_rest_" + std::to_string(c * per_channel + k - 1)); }, d);
}

// The file's splats as the rasterizer takes them, coloured for a camera at `eye` by inria_colour.
SurfelBatch<float> splats_for_view(const StrictPly& ply, int degree, Vec3d eye) {
    SurfelBatch<float> b;
    b.channels = 3;
    b.resize(ply.count);
    for (std::size_t i = 0; i < ply.count; ++i) {
        const Vec3d mean{ply.at(i, "x"), ply.at(i, "y"), ply.at(i, "z")};
        for (int k = 0; k < 3; ++k) b.means[3 * i + std::size_t(k)] = float(mean[k]);
        for (int k = 0; k < 4; ++k) b.quats[4 * i + std::size_t(k)] = ply.at(i, "rot_" + std::to_string(k));
        for (int k = 0; k < 2; ++k)
            b.scales[2 * i + std::size_t(k)] = std::exp(ply.at(i, "scale_" + std::to_string(k)));
        b.opacities[i] = float(1.0 / (1.0 + std::exp(-double(ply.at(i, "opacity")))));
        const Vec3d rgb = inria_colour(ply, i, degree, normalize(mean - eye));
        for (int c = 0; c < 3; ++c) b.colors[3 * i + std::size_t(c)] = float(rgb[c]);
    }
    return b;
}

struct ExportedFile {
    StrictPly ply;
    int degree = 0;
};

ExportedFile export_and_read(const TempDir& tmp, const GaussianModel& model, const ShCoeffs<float>& env,
                             BakeShading shading, int degree, const std::vector<Vec3d>& cameras) {
    const std::string path = tmp / ("baked_" + std::to_string(degree) + ".ply");
    const SurfelSides sides = bake_surfel_sides(model, env, shading);
    write_3dgs_ply(path, model, two_sided_view_sh(model, sides, degree, cameras), degree);
    return {read_strict_ply(path), degree};
}

TEST(ExportPly3dgs, StrictHeaderAndValuesForEveryDegree) {
    TempDir tmp("export_3dgs_strict");
    const GaussianModel model = cube_model(3, 25);
    const ShCoeffs<float> env = moderate_env();
    const SurfelSides sides = bake_surfel_sides(model, env, BakeShading::Shadowed);
    const std::vector<Vec3d> above = {{0, 0, 50}};
    for (int degree = 0; degree <= 3; ++degree) {
        const ExportedFile file = export_and_read(tmp, model, env, BakeShading::Shadowed, degree, above);
        const StrictPly& ply = file.ply;
        ASSERT_FALSE(::testing::Test::HasFailure()) << "degree " << degree;
        EXPECT_EQ(ply.count, model.size());
        EXPECT_EQ(ply.names, expected_properties(degree));
        EXPECT_EQ(ply_3dgs_property_names(degree), expected_properties(degree));
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
            // Degree 0: the side the camera above sees; else the DC is the mean of the two sides.
            const bool above_sees_positive = model.normal(i).z >= 0;
            for (int c = 0; c < 3; ++c) {
                const float pos = sides.positive[3 * i + std::size_t(c)];
                const float neg = sides.negative[3 * i + std::size_t(c)];
                const float expected = degree > 0 ? 0.5f * (pos + neg) : (above_sees_positive ? pos : neg);
                EXPECT_NEAR(0.5 + 0.28209479177387814 * ply.at(i, "f_dc_" + std::to_string(c)), expected,
                            1e-5);
            }
            double qn = 0, nn = 0;
            for (int k = 0; k < 4; ++k) qn += std::pow(ply.at(i, "rot_" + std::to_string(k)), 2);
            for (const char* n : {"nx", "ny", "nz"}) nn += std::pow(ply.at(i, n), 2);
            EXPECT_NEAR(qn, 1.0, 1e-5);
            EXPECT_NEAR(nn, 1.0, 1e-5);
            EXPECT_GE(ply.at(i, "rot_0") * model.param(ModelParam::Rotation)[4 * i], 0.0f);  // same sign
        }
    }
    EXPECT_THROW(two_sided_view_sh(model, sides, 4, above), Error);
    EXPECT_THROW(write_3dgs_ply(tmp / "bad.ply", model, std::vector<float>(3), 0), Error);
}

// Seen straight on, the degree-3 file's colour of each surfel is that side's baked colour within the step
// expansion's error at s = 1 (p(1) = 0.8: 0.2 of half the difference); seen from the other side, the other's.
TEST(ExportPly3dgs, EachSideShowsItsOwnColour) {
    TempDir tmp("export_3dgs_sides");
    const GaussianModel model = cube_model(5, 40);
    const ShCoeffs<float> env = moderate_env();
    const SurfelSides sides = bake_surfel_sides(model, env, BakeShading::Shadowed);
    const ExportedFile file = export_and_read(tmp, model, env, BakeShading::Shadowed, 3, {});
    for (std::size_t i = 0; i < model.size(); ++i) {
        const Vec3d n = model.normal(i).cast<double>();
        const Vec3d front = inria_colour(file.ply, i, 3, -n), back = inria_colour(file.ply, i, 3, n);
        for (int c = 0; c < 3; ++c) {
            const double pos = sides.positive[3 * i + std::size_t(c)],
                         neg = sides.negative[3 * i + std::size_t(c)];
            const double half = 0.5 * (pos - neg);
            EXPECT_NEAR(front[c], std::max(0.0, pos - 0.2 * half), 1e-4) << "surfel " << i;
            EXPECT_NEAR(back[c], std::max(0.0, neg + 0.2 * half), 1e-4) << "surfel " << i;
        }
    }
}

// The whole point: from cameras all around, the baked file renders like the relightable model. The old
// bake (one colour, the positive side: degree 0 without cameras) is shown to fail the same check.
void expect_two_sided_render(BakeShading bake, ShadingMode mode) {
    TempDir tmp("export_3dgs_render");
    const GaussianModel model = cube_model(7);
    const ShCoeffs<float> env = moderate_env();
    const ExportedFile degree3 = export_and_read(tmp, model, env, bake, 3, {});
    const ExportedFile degree1 = export_and_read(tmp, model, env, bake, 1, {});
    const ExportedFile positive_only = export_and_read(tmp, model, env, bake, 0, {});
    double worst3 = 1e9, worst1 = 1e9, worst_positive = 1e9;
    for (const Camera& cam : ring_cameras()) {
        const RasterImages<float> ref = render_with_environment(model, cam, env, mode);
        double covered = 0;
        for (float a : ref.alpha) covered += a;
        ASSERT_GT(covered, 0.2 * double(ref.alpha.size())) << "the camera sees too little";
        const auto psnr = [&](const ExportedFile& f) {
            RasterState<float> state;
            const RasterImages<float> back =
                rasterize_forward_cpu(cam, splats_for_view(f.ply, f.degree, cam.center()), {}, state);
            return display_psnr(back.color, ref.color);
        };
        worst3 = std::min(worst3, psnr(degree3));
        worst1 = std::min(worst1, psnr(degree1));
        worst_positive = std::min(worst_positive, psnr(positive_only));
    }
    std::printf("worst PSNR: degree 3 %.2f dB, degree 1 %.2f dB, one colour (+normal side) %.2f dB\n", worst3,
                worst1, worst_positive);
    EXPECT_GE(worst3, 30.0);
    EXPECT_GE(worst1, 25.0);
    EXPECT_GT(worst3, worst1);
    EXPECT_LT(worst_positive, worst1 - 5.0) << "one colour per surfel should show the back sides wrong";
}

TEST(ExportPly3dgs, RendersLikeTheModelFromBothSidesShadowed) {
    expect_two_sided_render(BakeShading::Shadowed, ShadingMode::Shadowed);
}

TEST(ExportPly3dgs, RendersLikeTheModelFromBothSidesUnshadowed) {
    expect_two_sided_render(BakeShading::Unshadowed, ShadingMode::Unshadowed);
}

// `--orient`: a file written in a turned world renders, from the turned cameras, like the model does from the
// original ones (the two-sided SH computed on the turned normals).
TEST(ExportPly3dgs, ATurnedFileRendersLikeTheModelFromTurnedCameras) {
    TempDir tmp("export_3dgs_turned");
    const GaussianModel model = cube_model(7);
    const ShCoeffs<float> env = moderate_env();
    const SurfelSides sides = bake_surfel_sides(model, env, BakeShading::Shadowed);
    const Mat3d R = orientation_rotation(ExportOrientation::YDown, {0.2, -0.3, 0.9});
    const TurnedWorld world = turn_world(model, {}, R);
    write_3dgs_ply(tmp / "turned.ply", world.model, two_sided_view_sh(world.model, sides, 3, world.cameras),
                   3);
    const StrictPly ply = read_strict_ply(tmp / "turned.ply");
    double worst = 1e9;
    for (Camera cam : ring_cameras()) {
        const RasterImages<float> ref = render_with_environment(model, cam, env, ShadingMode::Shadowed);
        cam.rotation = cam.rotation * transpose(R);  // the same view of the turned world
        RasterState<float> state;
        worst = std::min(
            worst,
            display_psnr(rasterize_forward_cpu(cam, splats_for_view(ply, 3, cam.center()), {}, state).color,
                         ref.color));
    }
    EXPECT_GE(worst, 30.0);
}

// One colour per surfel (degree 0, .splat): the side the given cameras see, weighted by |cos|; for a single
// camera that is exactly what it renders, so the file renders back to within float rounding.
TEST(ExportPly3dgs, OneColourIsTheSideTheCamerasSee) {
    TempDir tmp("export_3dgs_seen");
    const GaussianModel model = cube_model(9);
    const ShCoeffs<float> env = moderate_env();
    const Camera cam = ring_cameras()[2];
    const ExportedFile file = export_and_read(tmp, model, env, BakeShading::Shadowed, 0, {cam.center()});
    RasterState<float> state;
    const RasterImages<float> back =
        rasterize_forward_cpu(cam, splats_for_view(file.ply, 0, cam.center()), {}, state);
    const RasterImages<float> ref = render_with_environment(model, cam, env, ShadingMode::Shadowed);
    double max_diff = 0;
    for (std::size_t p = 0; p < ref.color.size(); ++p)
        max_diff = std::max(max_diff, double(std::abs(back.color[p] - ref.color[p])));
    EXPECT_LE(max_diff, 1e-5);

    // Two cameras on opposite sides of a surfel: the one seeing it more squarely wins.
    const SurfelSides sides = bake_surfel_sides(model, env, BakeShading::Shadowed);
    const Vec3d c0{model.param(ModelParam::Xyz)[0], model.param(ModelParam::Xyz)[1],
                   model.param(ModelParam::Xyz)[2]};
    const Vec3d n = model.normal(0).cast<double>();
    const Vec3d side = normalize(cross(n, std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}));
    const std::vector<Vec3d> squarely_behind = {c0 + 3.0 * (n + 0.2 * side), c0 - 3.0 * n};
    const std::vector<Vec3d> squarely_in_front = {c0 + 3.0 * n, c0 - 3.0 * (n + 2.0 * side)};
    EXPECT_EQ(seen_side_colours(model, sides, squarely_behind)[0], sides.negative[0]);
    EXPECT_EQ(seen_side_colours(model, sides, squarely_in_front)[0], sides.positive[0]);
    EXPECT_EQ(seen_side_colours(model, sides, {})[0], sides.positive[0]);
}

TEST(ExportPly3dgs, BakedColoursAreNotClampedAndShadingParses) {
    const GaussianModel model = cube_model(9, 30);
    ShCoeffs<float> hot = moderate_env();
    for (int k = 0; k < kShCount; ++k) hot.c[k] = hot.c[k] * 50.0f;
    const SurfelSides sides = bake_surfel_sides(model, hot, BakeShading::Unshadowed);
    float top = 0;
    for (float c : sides.positive) {
        EXPECT_GE(c, 0.0f);
        top = std::max(top, c);
    }
    EXPECT_GT(top, 1.0f) << "a 3DGS renderer clamps the pixel, not the splat";
    EXPECT_EQ(parse_bake_shading("shadowed"), BakeShading::Shadowed);
    EXPECT_EQ(parse_bake_shading("unshadowed"), BakeShading::Unshadowed);
    EXPECT_THROW(parse_bake_shading("both"), Error);
}

}  // namespace
}  // namespace lumigauss
