// viewer/model_payload.h and viewer/scene_info.h: what the viewer's page downloads. The payload is decoded
// here by a reader written from the documented layout alone, and must give back the model's raw parameters
// bit for bit; the scene description lists the lights in the documented order.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/util/error.h"
#include "lumigauss/viewer/model_payload.h"
#include "lumigauss/viewer/scene_info.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"

namespace lumigauss::view {
namespace {

struct DecodedPayload {
    std::uint32_t version = 0, count = 0, floats = 0;
    std::vector<float> xyz, rotation, scaling, opacity, albedo, positive, negative;
};

std::uint32_t read_u32(const std::string& b, std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v |= std::uint32_t(std::uint8_t(b.at(at + std::size_t(k)))) << (8 * k);
    return v;
}

// The reference reader: the layout of model_payload.h, nothing else.
DecodedPayload decode(const std::string& b) {
    DecodedPayload d;
    EXPECT_EQ(b.substr(0, 8), "LGVIEW01");
    d.version = read_u32(b, 8);
    d.count = read_u32(b, 12);
    d.floats = read_u32(b, 16);
    for (std::size_t at = 20; at < 32; ++at) EXPECT_EQ(b.at(at), '\0') << "reserved byte " << at;
    std::size_t at = 32;
    auto block = [&](std::vector<float>& out, int width) {
        out.resize(std::size_t(d.count) * std::size_t(width));
        for (float& v : out) {
            v = std::bit_cast<float>(read_u32(b, at));
            at += 4;
        }
    };
    block(d.xyz, 3), block(d.rotation, 4), block(d.scaling, 2), block(d.opacity, 1), block(d.albedo, 3);
    block(d.positive, 9), block(d.negative, 9);
    EXPECT_EQ(at, b.size()) << "trailing bytes";
    return d;
}

void expect_bits(const std::vector<float>& got, const std::vector<float>& want, const char* what) {
    ASSERT_EQ(got.size(), want.size()) << what;
    for (std::size_t i = 0; i < got.size(); ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(got[i]), std::bit_cast<std::uint32_t>(want[i]))
            << what << "[" << i << "]";
}

TEST(ViewModelPayload, DecodesBackToTheModelExactly) {
    GaussianModel model = relight_test::random_model(testing::test_camera(), 17, 57);
    // Values a float text round trip would lose: the payload must keep every bit.
    model.param(ModelParam::Xyz)[0] = std::nextafter(1.0f, 2.0f);
    model.param(ModelParam::Opacity)[1] = -0.0f;
    model.param(ModelParam::Albedo)[2] = 1e-38f;
    const std::string bytes = encode_model_payload(model);
    ASSERT_EQ(bytes.size(), kPayloadHeaderBytes + 57u * 31u * 4u);
    const DecodedPayload d = decode(bytes);
    EXPECT_EQ(d.version, 1u);
    EXPECT_EQ(d.count, 57u);
    EXPECT_EQ(d.floats, 31u);
    expect_bits(d.xyz, model.param(ModelParam::Xyz), "xyz");
    expect_bits(d.rotation, model.param(ModelParam::Rotation), "rotation");
    expect_bits(d.scaling, model.param(ModelParam::Scaling), "scaling");
    expect_bits(d.opacity, model.param(ModelParam::Opacity), "opacity");
    expect_bits(d.albedo, model.param(ModelParam::Albedo), "albedo");
    for (bool positive : {true, false}) {
        std::vector<float> want(57 * 9);
        for (std::size_t i = 0; i < 57; ++i) model.transfer_channel0(positive, i, &want[9 * i]);
        // Channel 0 is [k * 3 + 0] of the stored 27 (model/surfel_model.h).
        const auto& raw = model.param(positive ? ModelParam::TransferPositive : ModelParam::TransferNegative);
        EXPECT_EQ(want[9 * 5 + 4], raw[5 * 27 + 4 * 3]);
        expect_bits(positive ? d.positive : d.negative, want, positive ? "transfer+" : "transfer-");
    }
}

TEST(ViewModelPayload, EmptyModelIsJustTheHeader) {
    const std::string bytes =
        encode_model_payload(GaussianModel::from_raw(std::vector<std::vector<float>>(7), 1.0));
    EXPECT_EQ(bytes.size(), kPayloadHeaderBytes);
    EXPECT_EQ(decode(bytes).count, 0u);
}

TEST(ViewSceneInfo, ListsGivenLightsThenPhotosThenUniform) {
    const Camera cam = testing::test_camera();
    const TrainedRun run =
        relight_test::in_memory_run(relight_test::random_model(cam, 4, 30), {"p0.jpg", "p1.jpg"});
    ResolvedLight extra;
    extra.kind = LightKind::ShFile;
    extra.source = "/some/folder/sky_sh.txt";
    extra.sh = relight_test::bright_sh(9);
    const ViewerScene scene = describe_scene(run, {extra}, parse_up_axis("-y"), cam);
    const nlohmann::json j = nlohmann::json::parse(scene_json(scene));
    EXPECT_EQ(j["surfels"], 30);
    EXPECT_EQ(j["up_name"], "-y");
    ASSERT_EQ(j["lights"].size(), 4u);
    EXPECT_EQ(j["lights"][0]["name"], "sky_sh.txt");
    EXPECT_EQ(j["lights"][0]["kind"], "SH file");
    EXPECT_EQ(j["lights"][1]["name"], "p0.jpg");
    EXPECT_EQ(j["lights"][2]["name"], "p1.jpg");
    EXPECT_EQ(j["lights"][3]["name"], "uniform");
    const ShCoeffs<double> learned = run.learned_sh(1);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(j["lights"][0]["sh"][k][c].get<double>(), extra.sh.c[k][c]);
            EXPECT_EQ(j["lights"][2]["sh"][k][c].get<double>(), learned.c[k][c]);
        }
    // The orbit frame is right-handed about up, and the camera is passed through unchanged.
    const Vec3d e1{j["e1"][0], j["e1"][1], j["e1"][2]}, e2{j["e2"][0], j["e2"][1], j["e2"][2]};
    const Vec3d c = cross(e1, e2);
    EXPECT_NEAR(c.y, -1.0, 1e-12);
    EXPECT_EQ(j["camera"]["fx"].get<double>(), cam.fx);
    EXPECT_EQ(j["camera"]["R"][1][2].get<double>(), cam.rotation(1, 2));
    EXPECT_GT(j["radius"].get<double>(), 0.0);
    EXPECT_TRUE(j["sky_horizon"].is_null());  // trained without one
    EXPECT_TRUE(j["side_rule"].is_null());    // the official side rule
}

TEST(ViewSceneInfo, PassesTheRunsSkyHorizonToTheViewer) {
    const Camera cam = testing::test_camera();
    TrainedRun run = relight_test::in_memory_run(relight_test::random_model(cam, 4, 30), {"p0.jpg"});
    run.sky_background = true;
    run.sky_horizon = {{0, -1, 0}, 4, 4, {0.25f, 0.5f, 0.75f}};
    const nlohmann::json j =
        nlohmann::json::parse(scene_json(describe_scene(run, {}, parse_up_axis("-y"), cam)));
    EXPECT_EQ(j["sky_background"], true);
    EXPECT_EQ(j["sky_horizon"]["up"][1].get<double>(), -1.0);
    EXPECT_EQ(j["sky_horizon"]["start_degrees"].get<double>(), 4.0);
    EXPECT_EQ(j["sky_horizon"]["fade_degrees"].get<double>(), 4.0);
    EXPECT_EQ(j["sky_horizon"]["ground_albedo"][2].get<double>(), 0.75);  // the ground drawn below it
}

// Each training photo's light carries its sky residual when the run learned them, an SH file's light the
// residual of its "#sky" rows; the others none (the page then draws the light's sky alone).
TEST(ViewSceneInfo, LightsCarryTheirSkyResiduals) {
    const Camera cam = testing::test_camera();
    TrainedRun run =
        relight_test::in_memory_run(relight_test::random_model(cam, 4, 30), {"p0.jpg", "p1.jpg"});
    run.sky_residuals = SkyResiduals(2);
    run.sky_residuals.params()[SkyResiduals::kRowWidth + 3 * 24 + 1] = -0.25f;  // p1.jpg, k = 24, green
    ResolvedLight with_rows, without_rows;
    with_rows.kind = without_rows.kind = LightKind::ShFile;
    with_rows.source = "fitted.txt", without_rows.source = "plain.txt";
    with_rows.sky_residual = Sh4Coeffs<float>{};
    with_rows.sky_residual->c[9] = {0.75f, 0.0f, -0.5f};
    const nlohmann::json j = nlohmann::json::parse(
        scene_json(describe_scene(run, {with_rows, without_rows}, parse_up_axis("-y"), cam)));
    ASSERT_EQ(j["lights"].size(), 5u);
    ASSERT_EQ(j["lights"][0]["sky_residual"].size(), 25u);
    EXPECT_EQ(j["lights"][0]["sky_residual"][9][2].get<double>(), -0.5);
    EXPECT_FALSE(j["lights"][1].contains("sky_residual"));
    ASSERT_EQ(j["lights"][3]["sky_residual"].size(), 25u);  // p1.jpg
    EXPECT_EQ(j["lights"][3]["sky_residual"][24][1].get<double>(), -0.25);
    EXPECT_EQ(j["lights"][2]["sky_residual"][24][1].get<double>(), 0.0);  // p0.jpg's: all zero
    EXPECT_FALSE(j["lights"][4].contains("sky_residual"));                // uniform
    // A training photo named with --light brings its residual too (resolve_light).
    const ResolvedLight named = resolve_light("photo:p1.jpg", run, PanoramaOptions{});
    const nlohmann::json k =
        nlohmann::json::parse(scene_json(describe_scene(run, {named}, parse_up_axis("-y"), cam)));
    ASSERT_EQ(k["lights"][0]["sky_residual"].size(), 25u);
    EXPECT_EQ(k["lights"][0]["sky_residual"][24][1].get<double>(), -0.25);
    run.sky_residuals = SkyResiduals();
    const nlohmann::json bare =
        nlohmann::json::parse(scene_json(describe_scene(run, {}, parse_up_axis("-y"), cam)));
    EXPECT_FALSE(bare["lights"][0].contains("sky_residual")) << "a run without residuals";
}

// The viewer's shader picks each surfel's side as the run was trained (shading/surfel_side.h).
TEST(ViewSceneInfo, PassesTheRunsSideRuleToTheViewer) {
    const Camera cam = testing::test_camera();
    TrainedRun run = relight_test::in_memory_run(relight_test::random_model(cam, 4, 30), {"p0.jpg"});
    run.side_rule = {{0, -1, 0}, 5.0f};
    const nlohmann::json j =
        nlohmann::json::parse(scene_json(describe_scene(run, {}, parse_up_axis("-y"), cam)));
    EXPECT_EQ(j["side_rule"]["up"][1].get<double>(), -1.0);
    EXPECT_EQ(j["side_rule"]["grazing_degrees"].get<double>(), 5.0);
}

TEST(ViewSceneInfo, UniformEnvironmentHasIrradianceOne) {
    const ShCoeffs<double> u = uniform_environment();
    for (const Vec3d n : {Vec3d{0, 0, 1}, Vec3d{1, 0, 0}, normalize(Vec3d{-1, 2, -3})}) {
        const Vec3d e = irradiance(u, n);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], 1.0, 1e-12);
    }
}

TEST(ViewSceneInfo, CentreAndRadiusIgnoreStraySurfels) {
    const Camera cam = testing::test_camera();
    GaussianModel model = relight_test::random_model(cam, 5, 100);
    model.param(ModelParam::Xyz)[0] = 1e6f;  // one surfel far away
    const ViewerScene scene =
        describe_scene(relight_test::in_memory_run(std::move(model), {}), {}, {0, 0, 1}, {});
    EXPECT_LT(scene.radius, 20.0);
    EXPECT_EQ(scene.lights.size(), 1u);
    EXPECT_FALSE(scene.camera);
}

}  // namespace
}  // namespace lumigauss::view
