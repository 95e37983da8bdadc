// `export --format glb` (export/gltf_splats.h): the file read back by a reader written here from the glTF 2.0
// GLB container rules and the KHR_gaussian_splatting text (chunk layout and padding, accessors, 4-byte
// alignment, POSITION bounds, the extension object, attribute meanings: x y z w quaternions, linear scales,
// opacity after the sigmoid, one RGB attribute per SH coefficient), known values for one surfel, and the
// splats rendered with the Inria SH evaluation in glTF's y-up frame: they reproduce the relightable render
// of a z-up world from cameras all around.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>

#include "export_test_scene.h"
#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/gltf_splats.h"
#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/export/world_turn.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/util/error.h"
#include "support/inria_sh.h"

namespace lumigauss {
namespace {

using namespace lumigauss::export_test;
using Json = nlohmann::json;

std::uint32_t u32(const std::string& s, std::size_t at) {
    std::uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= std::uint32_t(std::uint8_t(s[at + std::size_t(b)])) << (8 * b);
    return v;
}

struct GltfSplats {
    Json gltf;
    std::size_t count = 0;
    int degree = -1;
    std::vector<Vec3d> position, scale;
    std::vector<Vec4<double>> xyzw;
    std::vector<double> opacity;
    std::vector<std::vector<Vec3d>> sh;  // [coefficient l^2 + l + m][splat]
    std::vector<std::array<double, 4>> colour_0;
};

// The GLB container, then the one primitive's attributes through their accessors and buffer views.
GltfSplats read_glb(const std::string& s) {
    GltfSplats f;
    EXPECT_GE(s.size(), 28u);
    if (s.size() < 28) return f;
    EXPECT_EQ(u32(s, 0), 0x46546C67u) << "magic";
    EXPECT_EQ(u32(s, 4), 2u) << "container version";
    EXPECT_EQ(u32(s, 8), s.size()) << "length";
    const std::size_t json_length = u32(s, 12);
    EXPECT_EQ(u32(s, 16), 0x4E4F534Au) << "first chunk JSON";
    EXPECT_EQ(json_length % 4, 0u);
    const std::string json = s.substr(20, json_length);
    const std::size_t last = json.find_last_not_of(' ');
    EXPECT_EQ(json[last], '}') << "the JSON chunk is padded with spaces";
    EXPECT_LT(json.size() - last - 1, 4u);
    const std::size_t bin_at = 20 + json_length;
    const std::size_t bin_length = u32(s, bin_at);
    EXPECT_EQ(u32(s, bin_at + 4), 0x004E4942u) << "second chunk BIN";
    EXPECT_EQ(bin_length % 4, 0u);
    EXPECT_EQ(bin_at + 8 + bin_length, s.size());
    const std::string bin = s.substr(bin_at + 8, bin_length);
    f.gltf = Json::parse(json);
    const Json& g = f.gltf;
    EXPECT_EQ(g["asset"]["version"], "2.0");
    EXPECT_EQ(g["extensionsUsed"], Json::array({"KHR_gaussian_splatting"}));
    EXPECT_FALSE(g.contains("extensionsRequired"))
        << "a viewer without the extension should still draw points";
    const std::size_t byte_length = g["buffers"][0]["byteLength"];
    EXPECT_FALSE(g["buffers"][0].contains("uri"));
    EXPECT_LE(byte_length, bin_length);
    EXPECT_LE(bin_length, byte_length + 3);
    EXPECT_EQ(g["nodes"][0]["mesh"], 0);
    EXPECT_EQ(g["scenes"][0]["nodes"], Json::array({0}));
    const Json& primitive = g["meshes"][0]["primitives"][0];
    EXPECT_EQ(primitive["mode"], 0) << "POINTS";
    const Json& ext = primitive["extensions"]["KHR_gaussian_splatting"];
    EXPECT_EQ(ext["kernel"], "ellipse");
    EXPECT_EQ(ext["colorSpace"], "srgb_rec709_display");
    const Json& attributes = primitive["attributes"];

    // One attribute: count x width values, floats or normalised unsigned bytes.
    const auto read = [&](const std::string& name, const char* type, int width) {
        std::vector<double> values;
        if (!attributes.contains(name)) {
            ADD_FAILURE() << "no attribute " << name;
            return values;
        }
        const Json& accessor = g["accessors"][attributes[name].get<std::size_t>()];
        const Json& view = g["bufferViews"][accessor["bufferView"].get<std::size_t>()];
        EXPECT_EQ(accessor["type"], type) << name;
        const std::size_t count = accessor["count"], offset = view["byteOffset"];
        const std::size_t at = offset + accessor.value("byteOffset", std::size_t(0));
        EXPECT_EQ(at % 4, 0u) << name << ": vertex attributes are 4-byte aligned";
        if (f.count == 0) f.count = count;
        EXPECT_EQ(count, f.count) << name << ": every attribute has the same count";
        const int component = accessor["componentType"];
        const std::size_t size = component == 5126 ? 4 : 1;
        EXPECT_TRUE(component == 5126 || (component == 5121 && accessor.value("normalized", false))) << name;
        EXPECT_GE(view["byteLength"].get<std::size_t>(), count * std::size_t(width) * size) << name;
        EXPECT_LE(at + count * std::size_t(width) * size, byte_length) << name;
        if (at + count * std::size_t(width) * size > bin.size()) return values;
        for (std::size_t k = 0; k < count * std::size_t(width); ++k) {
            if (size == 4) {
                float v = 0;
                std::memcpy(&v, bin.data() + at + 4 * k, 4);
                values.push_back(v);
            } else {
                values.push_back(double(std::uint8_t(bin[at + k])) / 255.0);
            }
        }
        return values;
    };
    const std::vector<double> p = read("POSITION", "VEC3", 3);
    const std::vector<double> q = read("KHR_gaussian_splatting:ROTATION", "VEC4", 4);
    const std::vector<double> sc = read("KHR_gaussian_splatting:SCALE", "VEC3", 3);
    const std::vector<double> op = read("KHR_gaussian_splatting:OPACITY", "SCALAR", 1);
    const std::vector<double> c0 = read("COLOR_0", "VEC4", 4);
    for (int l = 0; l <= 3; ++l) {
        if (!attributes.contains("KHR_gaussian_splatting:SH_DEGREE_" + std::to_string(l) + "_COEF_0")) break;
        f.degree = l;
        for (int n = 0; n <= 2 * l; ++n) {
            const std::vector<double> v =
                read("KHR_gaussian_splatting:SH_DEGREE_" + std::to_string(l) + "_COEF_" + std::to_string(n),
                     "VEC3", 3);
            f.sh.emplace_back();
            for (std::size_t i = 0; 3 * i + 2 < v.size(); ++i)
                f.sh.back().push_back({v[3 * i], v[3 * i + 1], v[3 * i + 2]});
        }
    }
    const Json& pos_accessor = g["accessors"][attributes["POSITION"].get<std::size_t>()];
    for (std::size_t i = 0; 3 * i + 2 < p.size(); ++i) {
        f.position.push_back({p[3 * i], p[3 * i + 1], p[3 * i + 2]});
        for (int k = 0; k < 3; ++k) {
            EXPECT_GE(p[3 * i + std::size_t(k)], pos_accessor["min"][std::size_t(k)].get<double>());
            EXPECT_LE(p[3 * i + std::size_t(k)], pos_accessor["max"][std::size_t(k)].get<double>());
        }
    }
    for (std::size_t i = 0; 4 * i + 3 < q.size(); ++i)
        f.xyzw.push_back({q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]});
    for (std::size_t i = 0; 3 * i + 2 < sc.size(); ++i)
        f.scale.push_back({sc[3 * i], sc[3 * i + 1], sc[3 * i + 2]});
    f.opacity = op;
    for (std::size_t i = 0; 4 * i + 3 < c0.size(); ++i)
        f.colour_0.push_back({c0[4 * i], c0[4 * i + 1], c0[4 * i + 2], c0[4 * i + 3]});
    return f;
}

SurfelModel one_surfel() {
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(std::size_t(SurfelModel::width(ModelParam(p))), 0.0f);
    raw[int(ModelParam::Xyz)] = {1.0f, -2.0f, 0.5f};
    raw[int(ModelParam::Rotation)] = {0.2f, 0.4f, -0.8f, 0.4f};  // length 1 after a factor 1
    raw[int(ModelParam::Scaling)] = {-1.0f, -2.0f};
    raw[int(ModelParam::Opacity)] = {2.0f};
    return SurfelModel::from_raw(std::move(raw));
}

TEST(ExportGltf, OneSurfelKnownValues) {
    const SurfelModel model = one_surfel();
    // Degree 1, coefficient-major RGB: DC (0.1, 0.2, 0.3), then 0.01 k + 0.001 c.
    std::vector<float> view_sh = {0.1f, 0.2f, 0.3f};
    for (int k = 1; k < 4; ++k)
        for (int c = 0; c < 3; ++c) view_sh.push_back(0.01f * float(k) + 0.001f * float(c));
    const GltfSplats f = read_glb(gltf_splats_glb(model, view_sh, 1));
    ASSERT_EQ(f.count, 1u);
    ASSERT_EQ(f.degree, 1);
    EXPECT_EQ(f.position[0].x, 1.0);
    EXPECT_EQ(f.position[0].y, -2.0);
    EXPECT_EQ(f.position[0].z, 0.5);
    EXPECT_EQ(f.gltf["accessors"][0]["min"], Json::array({1.0, -2.0, 0.5}));
    // (w x y z) = (0.2, 0.4, -0.8, 0.4) stored as x y z w.
    EXPECT_NEAR(f.xyzw[0][0], 0.4, 1e-6);
    EXPECT_NEAR(f.xyzw[0][1], -0.8, 1e-6);
    EXPECT_NEAR(f.xyzw[0][2], 0.4, 1e-6);
    EXPECT_NEAR(f.xyzw[0][3], 0.2, 1e-6);
    EXPECT_NEAR(f.scale[0].x, std::exp(-1.0), 1e-7);
    EXPECT_NEAR(f.scale[0].y, std::exp(-2.0), 1e-7);
    EXPECT_NEAR(f.scale[0].z, 1e-6, 1e-12);
    EXPECT_NEAR(f.opacity[0], 1 / (1 + std::exp(-2.0)), 1e-7);
    EXPECT_NEAR(f.sh[0][0].y, 0.2, 1e-7);
    EXPECT_NEAR(f.sh[3][0].z, 0.032, 1e-7) << "SH_DEGREE_1_COEF_2 is coefficient 3 (m = +1), blue";
    // COLOR_0: the DC colour 0.5 + Y00 SH0 made linear, and the opacity.
    const double display = 0.5 + 0.28209479177387814 * 0.3;
    EXPECT_NEAR(f.colour_0[0][2], std::pow((display + 0.055) / 1.055, 2.4), 0.5 / 255 + 1e-9);
    EXPECT_NEAR(f.colour_0[0][3], 1 / (1 + std::exp(-2.0)), 0.5 / 255 + 1e-9);

    EXPECT_THROW((void)gltf_splats_glb(model, view_sh, 2), Error) << "degree 2 needs 27 values";
    EXPECT_THROW((void)gltf_splats_glb(model, view_sh, 4), Error);
}

// `cam` (world frame) in the turned frame p' = R p: world-to-camera rotation Rc R^T, same translation.
Camera turned_camera(Camera cam, const Mat3d& R) {
    cam.rotation = cam.rotation * transpose(R);
    return cam;
}

SurfelBatch<float> splats_for_view(const GltfSplats& f, Vec3d eye) {
    SurfelBatch<float> b;
    b.channels = 3;
    b.resize(f.count);
    for (std::size_t i = 0; i < f.count; ++i) {
        for (int k = 0; k < 3; ++k) b.means[3 * i + std::size_t(k)] = float(f.position[i][k]);
        const Vec4<double>& q = f.xyzw[i];
        const double wxyz[4] = {q[3], q[0], q[1], q[2]};
        for (int k = 0; k < 4; ++k) b.quats[4 * i + std::size_t(k)] = float(wxyz[k]);
        for (int k = 0; k < 2; ++k) b.scales[2 * i + std::size_t(k)] = float(f.scale[i][k]);
        b.opacities[i] = float(f.opacity[i]);
        const double dc[3] = {f.sh[0][i].x, f.sh[0][i].y, f.sh[0][i].z};
        const Vec3d rgb = lumigauss::testing::inria_sh_colour(
            f.degree, dc, [&](int k, int c) { return f.sh[std::size_t(k)][i][c]; },
            normalize(f.position[i] - eye));
        for (int c = 0; c < 3; ++c) b.colors[3 * i + std::size_t(c)] = float(rgb[c]);
    }
    return b;
}

// A z-up world exported as the CLI does (turned to glTF's +y, the SH computed in the turned frame): seen
// from cameras all around, the file renders like the relightable model, both sides of every surfel.
TEST(ExportGltf, RendersLikeTheModelFromBothSidesInTheYUpFrame) {
    const GaussianModel model = cube_model(7);
    const ShCoeffs<float> env = moderate_env();
    const SurfelSides sides = bake_surfel_sides(model, env, BakeShading::Shadowed);
    const Mat3d R = orientation_rotation(ExportOrientation::YUp, {0, 0, 1});
    const TurnedWorld world = turn_world(model, {}, R);
    const GltfSplats three =
        read_glb(gltf_splats_glb(world.model, two_sided_view_sh(world.model, sides, 3, {}), 3));
    const GltfSplats one =
        read_glb(gltf_splats_glb(world.model, two_sided_view_sh(world.model, sides, 0, {}), 0));
    ASSERT_EQ(three.count, model.size());
    EXPECT_EQ(three.degree, 3);
    EXPECT_EQ(one.degree, 0);
    double worst = 1e9, worst_one = 1e9;
    for (const Camera& cam : ring_cameras()) {
        const RasterImages<float> ref = render_with_environment(model, cam, env, ShadingMode::Shadowed);
        const Camera turned = turned_camera(cam, R);
        const auto psnr = [&](const GltfSplats& f) {
            RasterState<float> state;
            return display_psnr(
                rasterize_forward_cpu(turned, splats_for_view(f, turned.center()), {}, state).color,
                ref.color);
        };
        worst = std::min(worst, psnr(three));
        worst_one = std::min(worst_one, psnr(one));
    }
    std::printf("worst PSNR: glTF degree 3 %.2f dB, one colour %.2f dB\n", worst, worst_one);
    EXPECT_GE(worst, 33.0);
    EXPECT_LT(worst_one, worst - 5.0);
}

}  // namespace
}  // namespace lumigauss
