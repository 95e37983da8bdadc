// The relighting render (relight/relit_render.h): its colour channels are what render_with_environment
// renders (training photo light == lighting.env_sh(i), SH light == that SH, turns as sh_rotation), its
// intensity and albedo channels are consistent with the colour, and the official shadow image is 1 (no
// shadow) where the transfer is the unoccluded cosine lobe, lower where it is occluded.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/shading/surfel_shading.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;

struct Diff {
    double max = 0;
    double sum = 0;
};

// Channels [first, first + count) of a relit raster against all channels of a reference buffer.
Diff channel_diff(const RasterImages<float>& relit, int first, int count, const std::vector<float>& ref,
                  int ref_channels, int ref_first) {
    Diff d;
    const std::size_t pixels = std::size_t(relit.width) * std::size_t(relit.height);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < count; ++c) {
            const double a = relit.color[p * kRelitChannels + std::size_t(first + c)];
            const double b = ref[p * std::size_t(ref_channels) + std::size_t(ref_first + c)];
            d.max = std::max(d.max, std::abs(a - b));
            d.sum += std::abs(b);
        }
    return d;
}

double max_diff(const std::vector<float>& a, const std::vector<float>& b) {
    EXPECT_EQ(a.size(), b.size());
    double m = 0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
        m = std::max(m, double(std::abs(a[i] - b[i])));
    return m;
}

void expect_same_render(const RasterImages<float>& relit, const RasterImages<float>& both) {
    ASSERT_EQ(relit.channels, kRelitChannels);
    ASSERT_EQ(both.channels, kSurfelColourChannels);
    const Diff s = channel_diff(relit, kRelitShadowed, 3, both.color, 6, kShadowedOffset);
    const Diff u = channel_diff(relit, kRelitUnshadowed, 3, both.color, 6, kUnshadowedOffset);
    EXPECT_LE(s.max, 1e-6);
    EXPECT_LE(u.max, 1e-6);
    EXPECT_GT(s.sum, 100.0) << "something must be rendered";
    EXPECT_GT(u.sum, 100.0);
    EXPECT_LE(max_diff(relit.alpha, both.alpha), 1e-6);
    EXPECT_LE(max_diff(relit.depth, both.depth), 1e-5);
    EXPECT_LE(max_diff(relit.normal, both.normal), 1e-6);
}

const std::vector<std::string> kNames = {"p0.png", "p1.png", "p2.png"};

TEST(RelightRender, TrainingPhotoLightRendersAsRenderWithEnvironment) {
    const Camera cam = testing::test_camera(48, 40);
    TrainedRun run = relight_test::in_memory_run(relight_test::random_model(cam, 21), kNames, 99);
    // Bright learned lights (a positive DC from the output bias), so the colours are well above the floor.
    for (int ch = 0; ch < 3; ++ch) run.lighting.param(MlpGroup::kB3)[std::size_t(ch * kShCount)] += 3.0f;
    RelitRenderer renderer(run.model);
    for (int i = 0; i < 3; ++i) {
        const ResolvedLight light = resolve_light(kNames[std::size_t(i)], run, {});
        const ShCoeffs<float> learned = run.lighting.env_sh(i);
        const ShCoeffs<float> env = light.sh.cast<float>();
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) ASSERT_EQ(env.c[k][c], learned.c[k][c]);
        const RasterImages<float>& relit = renderer.render(cam, env);
        const RasterImages<float> both = render_with_environment(run.model, cam, learned, ShadingMode::Both);
        expect_same_render(relit, both);
    }
}

TEST(RelightRender, ShFileLightRendersAsThatSh) {
    TempDir tmp("relight_render_sh");
    const Camera cam = testing::test_camera(48, 40);
    const TrainedRun run = relight_test::in_memory_run(relight_test::random_model(cam, 22), kNames);
    const ShCoeffs<double> sh = relight_test::bright_sh(23);
    write_sh_text(tmp / "env.txt", sh);
    const ResolvedLight light = resolve_light(tmp / "env.txt", run, {});
    RelitRenderer renderer(run.model);
    const RasterImages<float>& relit = renderer.render(cam, light.sh.cast<float>());
    const RasterImages<float> both = render_with_environment(
        run.model, cam, read_sh_text(tmp / "env.txt").cast<float>(), ShadingMode::Both);
    expect_same_render(relit, both);
}

TEST(RelightRender, TurnsRenderAsRotatedSh) {
    const Camera cam = testing::test_camera(48, 40);
    const GaussianModel model = relight_test::random_model(cam, 24);
    const ShCoeffs<double> sh = relight_test::bright_sh(25);
    const Vec3d up{0, 0, 1};
    RelitRenderer renderer(model);
    // 360 deg == no turn.
    const RasterImages<float> full = renderer.render(cam, rotate_about_up(sh, up, 360).cast<float>());
    const RasterImages<float> none = renderer.render(cam, sh.cast<float>());
    EXPECT_LE(max_diff(full.color, none.color), 1e-5);
    // 90 deg == the SH rotated by sh_rotation about up.
    const ShCoeffs<double> quarter = rotate_sh(sh, rotation_about_axis(up, std::numbers::pi / 2));
    const RasterImages<float>& turned = renderer.render(cam, rotate_about_up(sh, up, 90).cast<float>());
    const RasterImages<float> both =
        render_with_environment(model, cam, quarter.cast<float>(), ShadingMode::Both);
    expect_same_render(turned, both);
    EXPECT_GT(max_diff(turned.color, none.color), 1e-3) << "a quarter turn must change the render";
}

TEST(RelightRender, IntensityAndAlbedoChannelsAreConsistentWithTheColour) {
    // Every surfel with the same albedo a: colour = a * intensity pixel by pixel (blending is linear), and
    // the albedo channel is a * alpha.
    const Camera cam = testing::test_camera(48, 40);
    auto raw = relight_test::random_raw(cam, 26, 60);
    const float a[3] = {0.3f, 0.55f, 0.8f};
    for (std::size_t i = 0; i < 60; ++i)
        for (int c = 0; c < 3; ++c)
            raw[int(ModelParam::Albedo)][3 * i + std::size_t(c)] = float((a[c] - 0.5) / sh_const::kY00);
    const GaussianModel model = GaussianModel::from_raw(std::move(raw), 1.0);
    RelitRenderer renderer(model);
    const RasterImages<float>& r = renderer.render(cam, relight_test::bright_sh(27).cast<float>());
    const std::size_t pixels = std::size_t(r.width) * std::size_t(r.height);
    double covered = 0;
    for (std::size_t p = 0; p < pixels; ++p) {
        const float* px = &r.color[p * kRelitChannels];
        covered += r.alpha[p];
        for (int c = 0; c < 3; ++c) {
            const float albedo = a[c];  // max(0, Y00 raw + 0.5) of the raw value set above
            EXPECT_NEAR(px[kRelitShadowed + c], albedo * px[kRelitIntensityShadowed + c], 2e-5) << p;
            EXPECT_NEAR(px[kRelitUnshadowed + c], albedo * px[kRelitIntensityUnshadowed + c], 2e-5) << p;
            EXPECT_NEAR(px[kRelitAlbedo + c], albedo * r.alpha[p], 1e-5) << p;
        }
    }
    EXPECT_GT(covered, 20.0);
}

// Transfer of the side each surfel shows the camera := `factor` * cosine lobe of its camera-facing normal.
GaussianModel lobe_model(const Camera& cam, double factor) {
    GaussianModel m = relight_test::random_model(cam, 28, 80);
    ViewNormals vn;
    compute_view_normals(m, cam, vn);
    for (std::size_t i = 0; i < m.size(); ++i) {
        float lobe[kShCount];
        cosine_lobe_sh(vn.normal[i], lobe);
        auto& used =
            m.param(vn.positive_side[i] ? ModelParam::TransferPositive : ModelParam::TransferNegative);
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c)
                used[i * kTransferStored + std::size_t(3 * k + c)] = float(factor) * lobe[k];
    }
    return m;
}

TEST(RelightRender, ShadowImageIsOneWhereTheTransferIsTheCosineLobe) {
    const Camera cam = testing::test_camera(48, 40);
    ShCoeffs<double> sh = relight_test::bright_sh(29);
    sh.c[0] = Vec3d{4, 4, 4};  // irradiance well above the 1e-5 floor for every normal
    const GaussianModel unoccluded = lobe_model(cam, 1.0);
    RelitRenderer renderer(unoccluded);
    const RasterImages<float>& r = renderer.render(cam, sh.cast<float>());
    const Image iu = raster_channels(r, kRelitIntensityUnshadowed, 3);
    const Image is = raster_channels(r, kRelitIntensityShadowed, 3);
    const Image shadow = shadow_image(iu, is);
    double covered = 0;
    for (std::size_t p = 0; p < shadow.pixels.size(); ++p) {
        EXPECT_NEAR(shadow.pixels[p], 1.0f, 1e-5f) << p;
        covered += r.alpha[p];
    }
    EXPECT_GT(covered, 20.0);

    // Half the light blocked: the shadow image drops where something is rendered.
    const GaussianModel occluded = lobe_model(cam, 0.5);
    RelitRenderer dark(occluded);
    const RasterImages<float>& d = dark.render(cam, sh.cast<float>());
    const Image dshadow = shadow_image(raster_channels(d, kRelitIntensityUnshadowed, 3),
                                       raster_channels(d, kRelitIntensityShadowed, 3));
    int darker = 0, opaque = 0;
    for (std::size_t p = 0; p < dshadow.pixels.size(); ++p) {
        if (d.alpha[p] < 0.5f) continue;
        ++opaque;
        darker += dshadow.pixels[p] < 0.99f;
        EXPECT_LE(dshadow.pixels[p], 1.0f);
    }
    EXPECT_GT(opaque, 10);
    EXPECT_EQ(darker, opaque);
}

TEST(RelightRender, ShadowImageFormula) {
    Image u(3, 1, 3), s(3, 1, 3);
    // Pixel 0: no difference; pixel 1: difference 0.5 grey; pixel 2: shadowed brighter (clamped at 0).
    for (int c = 0; c < 3; ++c) {
        u.at(0, 0, c) = 0.7f, s.at(0, 0, c) = 0.7f;
        u.at(1, 0, c) = 0.9f, s.at(1, 0, c) = 0.4f;
        u.at(2, 0, c) = 0.2f, s.at(2, 0, c) = 0.6f;
    }
    u.at(1, 0, 1) = 1.4f;  // green weighs 0.7152
    const Image sh = shadow_image(u, s);
    EXPECT_FLOAT_EQ(sh.pixels[0], 1.0f);
    EXPECT_NEAR(sh.pixels[1], 1.0f - (0.2126f * 0.5f + 0.7152f * 1.0f + 0.0722f * 0.5f), 1e-6f);
    EXPECT_FLOAT_EQ(sh.pixels[2], 1.0f);
}

TEST(RelightRender, MapsFromTheRaster) {
    RasterImages<float> r;
    r.width = 2, r.height = 1, r.channels = kRelitChannels;
    r.alpha = {0.5f, 0.0f};
    r.depth = {1.5f, 0.0f};
    r.normal = {0.0f, 0.0f, -0.5f, 0.0f, 0.0f, 0.0f};
    EXPECT_FLOAT_EQ(expected_depth(r).pixels[0], 3.0f);
    EXPECT_FLOAT_EQ(expected_depth(r).pixels[1], 0.0f);
    const Image n = encode_normals(r);
    EXPECT_FLOAT_EQ(n.pixels[0], 0.5f);
    EXPECT_FLOAT_EQ(n.pixels[2], 0.0f);  // (-1 + 1) / 2
    EXPECT_FLOAT_EQ(n.pixels[3], 0.0f);  // nothing rendered
    EXPECT_FLOAT_EQ(unit_normals(r).pixels[2], -1.0f);
    Image big(1, 1, 3, 0.5f);
    big.pixels[1] = 2.0f;
    EXPECT_FLOAT_EQ(display_max({&big}), 2.0f);
    Image small(1, 1, 3, 0.5f);
    EXPECT_FLOAT_EQ(display_max({&small}), 1.0f);
    Image colour(2, 1, 3, 0.25f), alpha(2, 1, 1, 1.0f);
    alpha.pixels[1] = 0.0f;
    const Image over = over_background(colour, alpha, Vec3f{1, 0, 0});
    EXPECT_FLOAT_EQ(over.pixels[0], 0.25f);
    EXPECT_FLOAT_EQ(over.pixels[3], 1.25f);
    EXPECT_FLOAT_EQ(over.pixels[4], 0.25f);
}

}  // namespace
}  // namespace lumigauss
