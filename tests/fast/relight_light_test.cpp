// What `render RUN --light L` turns L into (relight/light_source.h) and how the environment is turned
// (cameras/up_axis.h): a training photo gives exactly lighting.env_sh(i), an SH file its 9 rows, a
// panorama its projection (with the official fake HDR boost for LDR files only); 360 deg is no turn and
// 90 deg is sh_rotation's turn about the up axis.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/image.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using ::testing::HasSubstr;

const std::vector<std::string> kNames = {"a.png", "sub/b.jpg", "c.png"};

TrainedRun small_run() {
    return relight_test::in_memory_run(relight_test::random_model(testing::test_camera(), 3, 8), kNames);
}

void expect_sh_eq(const ShCoeffs<double>& a, const ShCoeffs<double>& b, double tol = 0.0) {
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a.c[k][c], b.c[k][c], tol) << "coefficient " << k << " channel " << c;
}

double max_abs_diff(const ShCoeffs<double>& a, const ShCoeffs<double>& b) {
    double m = 0;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(a.c[k][c] - b.c[k][c]));
    return m;
}

std::string message_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

// A 32 x 16 panorama with a bright spot, values in [0, 1] (some exactly 1).
Image test_panorama() {
    Image pano(32, 16, 3);
    for (int y = 0; y < pano.height; ++y)
        for (int x = 0; x < pano.width; ++x)
            for (int c = 0; c < 3; ++c)
                pano.at(x, y, c) = float(0.2 + 0.1 * c + 0.3 * std::sin(0.4 * x) * std::cos(0.3 * y)) * 0.8f;
    for (int y = 3; y < 5; ++y)
        for (int x = 10; x < 13; ++x)
            for (int c = 0; c < 3; ++c) pano.at(x, y, c) = 1.0f;
    return pano;
}

// ---- Training photos ------------------------------------------------------------------------------------

TEST(RelightLight, TrainingPhotoIsItsLearnedLight) {
    const TrainedRun run = small_run();
    for (int i = 0; i < 3; ++i) {
        const ResolvedLight l = resolve_light(kNames[std::size_t(i)], run, {});
        EXPECT_EQ(l.kind, LightKind::Photo);
        EXPECT_EQ(l.photo_index, i);
        expect_sh_eq(l.sh, run.lighting.env_sh(i).cast<double>());
    }
    // By stem, and with the explicit prefix.
    EXPECT_EQ(resolve_light("sub/b", run, {}).photo_index, 1);
    EXPECT_EQ(resolve_light("photo:c.png", run, {}).photo_index, 2);
    EXPECT_EQ(resolve_light("photo:c", run, {}).photo_index, 2);
}

TEST(RelightLight, UnknownNameListsSomePhotos) {
    const TrainedRun run = small_run();
    const std::string msg = message_of([&] { resolve_light("nope.png", run, {}); });
    EXPECT_THAT(msg, HasSubstr("nope.png"));
    EXPECT_THAT(msg, HasSubstr("a.png"));
    EXPECT_THAT(msg, HasSubstr("sub/b.jpg"));
    EXPECT_THAT(msg, HasSubstr("appearance.json"));
    EXPECT_THAT(message_of([&] { resolve_light("photo:zzz", run, {}); }), HasSubstr("zzz"));
}

// ---- Files ----------------------------------------------------------------------------------------------

TEST(RelightLight, ShTextFileIsItsCoefficients) {
    TempDir tmp("relight_sh_file");
    const ShCoeffs<double> sh = relight_test::bright_sh(5);
    write_sh_text(tmp / "env.txt", sh);
    const TrainedRun run = small_run();
    const ResolvedLight l = resolve_light(tmp / "env.txt", run, {});
    EXPECT_EQ(l.kind, LightKind::ShFile);
    expect_sh_eq(l.sh, read_sh_text(tmp / "env.txt"));
    expect_sh_eq(l.sh, sh, 1e-8);
    expect_sh_eq(resolve_light("sh:" + tmp / "env.txt", run, {}).sh, l.sh);
    // A malformed SH file names itself.
    write_sh_text(tmp / "bad.txt", sh);
    {
        std::ofstream f(tmp / "bad.txt", std::ios::app);
        f << "1 2 3\n";
    }
    EXPECT_THAT(message_of([&] { resolve_light(tmp / "bad.txt", run, {}); }), HasSubstr("bad.txt"));
}

TEST(RelightLight, HdrPanoramaIsItsProjectionInTheUpFrame) {
    TempDir tmp("relight_pano_exr");
    const Image pano = test_panorama();
    write_exr(tmp / "sky.exr", pano);
    const TrainedRun run = small_run();
    for (const char* up : {"+z", "-y", "+x"}) {
        PanoramaOptions o;
        o.frame = panorama_frame_for_up(parse_up_axis(up));
        o.hdr_scale = 10;  // ignored: not an LDR file
        const ResolvedLight l = resolve_light(tmp / "sky.exr", run, o);
        EXPECT_EQ(l.kind, LightKind::Panorama);
        EXPECT_FALSE(l.boosted);
        expect_sh_eq(l.sh, project_panorama_to_sh(pano, o.frame), 1e-12);
    }
}

TEST(RelightLight, LdrPanoramaGetsTheFakeHdrBoostAboveTheThreshold) {
    TempDir tmp("relight_pano_png");
    const Image pano = test_panorama();
    write_png(tmp / "sky.png", pano);
    const Image stored = read_image(tmp / "sky.png");  // 8-bit codes / 255, no linearisation
    const TrainedRun run = small_run();

    PanoramaOptions off;
    const ResolvedLight plain = resolve_light(tmp / "sky.png", run, off);
    EXPECT_FALSE(plain.boosted);
    expect_sh_eq(plain.sh, project_panorama_to_sh(stored), 1e-12);

    PanoramaOptions on;
    on.hdr_threshold = 0.99;
    on.hdr_scale = 10;
    Image boosted = stored;
    std::size_t above = 0;
    for (float& v : boosted.pixels)
        if (v > 0.99f) v *= 10, ++above;
    EXPECT_EQ(above, 2u * 3u * 3u);  // the bright spot, every channel
    const ResolvedLight l = resolve_light("pano:" + tmp / "sky.png", run, on);
    EXPECT_TRUE(l.boosted);
    expect_sh_eq(l.sh, project_panorama_to_sh(boosted), 1e-9);
    EXPECT_GT(l.sh.c[0].x, plain.sh.c[0].x);
}

TEST(RelightLight, FakeHdrBoostLeavesAlphaAlone) {
    Image rgba(2, 1, 4, 1.0f);
    rgba.at(1, 0, 0) = 0.5f;
    EXPECT_EQ(fake_hdr_boost(rgba, 0.9, 3.0), 5u);
    EXPECT_FLOAT_EQ(rgba.at(0, 0, 0), 3.0f);
    EXPECT_FLOAT_EQ(rgba.at(1, 0, 0), 0.5f);
    EXPECT_FLOAT_EQ(rgba.at(0, 0, 3), 1.0f);
}

TEST(RelightLight, UnreadableOrUnknownFilesNameThemselves) {
    TempDir tmp("relight_bad_files");
    const TrainedRun run = small_run();
    {
        std::ofstream f(tmp / "broken.png");
        f << "not a png";
        std::ofstream g(tmp / "notes.md");
        g << "hello";
    }
    EXPECT_THAT(message_of([&] { resolve_light(tmp / "broken.png", run, {}); }), HasSubstr("broken.png"));
    EXPECT_THAT(message_of([&] { resolve_light(tmp / "notes.md", run, {}); }), HasSubstr("notes.md"));
    EXPECT_THAT(message_of([&] { resolve_light("pano:" + tmp / "missing.exr", run, {}); }),
                HasSubstr("missing.exr"));
}

// ---- Exposure -------------------------------------------------------------------------------------------

TEST(RelightLight, MatchExposureGivesTheMedianLearnedBrightness) {
    TrainedRun run = small_run();
    // A positive DC in every learned light: raise the output bias of the DC coefficient of each channel.
    for (int ch = 0; ch < 3; ++ch) run.lighting.param(MlpGroup::kB3)[std::size_t(ch * kShCount)] += 5.0f;
    std::vector<double> lumas;
    for (int i = 0; i < 3; ++i) lumas.push_back(dc_luma(run.learned_sh(i)));
    std::sort(lumas.begin(), lumas.end());
    ShCoeffs<double> sh = relight_test::bright_sh(9);
    ASSERT_GT(lumas[0], 0.0);
    const double f = match_exposure_factor(sh, run);
    EXPECT_NEAR(dc_luma(scaled(sh, f)), lumas[1], 1e-12 * lumas[1]);
    ShCoeffs<double> dark;
    EXPECT_THROW(match_exposure_factor(dark, run), Error);
}

// ---- Turning the environment ----------------------------------------------------------------------------

TEST(RelightLight, UpAxisParsing) {
    EXPECT_EQ(parse_up_axis("z").z, 1.0);
    EXPECT_EQ(parse_up_axis("+Z").z, 1.0);
    EXPECT_EQ(parse_up_axis("-y").y, -1.0);
    EXPECT_EQ(parse_up_axis("x").x, 1.0);
    EXPECT_THROW(parse_up_axis("w"), Error);
    EXPECT_THROW(parse_up_axis(""), Error);
    EXPECT_THROW(parse_up_axis("+"), Error);
    EXPECT_EQ(up_axis_name(parse_up_axis("-y")), "-y");
    // Any vector, normalized; its name reads back.
    const Vec3d v = parse_up_axis("0.1, -2,0.2");
    EXPECT_NEAR(length(v - normalize(Vec3d{0.1, -2, 0.2})), 0.0, 1e-15);
    EXPECT_NEAR(length(parse_up_axis(up_axis_name(v)) - v), 0.0, 1e-6);
    EXPECT_EQ(up_axis_name(parse_up_axis("0,0,3")), "+z");
    for (const char* bad : {"0,0,0", "1,2", "1,2,3,4", "1,,2", "1,nan,2", "1,2,x", "auto"})
        EXPECT_THROW(parse_up_axis(bad), Error) << bad;
}

TEST(RelightLight, PanoramaFrameLooksUpAndIsARotation) {
    for (const char* name : {"+x", "-x", "+y", "-y", "+z", "-z"}) {
        const Vec3d up = parse_up_axis(name);
        const Mat3d f = panorama_frame_for_up(up);
        const Vec3d top = f * Vec3d{0, 0, 1};
        EXPECT_NEAR(length(top - up), 0.0, 1e-12) << name;
        const Mat3d i = f * transpose(f);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(i(r, c), r == c ? 1.0 : 0.0, 1e-12) << name;
        EXPECT_NEAR(dot(cross(f.col(0), f.col(1)), f.col(2)), 1.0, 1e-12) << name;
    }
    // Any other up: a rotation whose top row is up, continuous with the nearest axis's frame.
    for (const Vec3d up :
         {normalize(Vec3d{0.05, -1, 0.1}), normalize(Vec3d{1, 1, 1.2}), normalize(Vec3d{-0.3, 0.2, -1})}) {
        const Mat3d f = panorama_frame_for_up(up);
        EXPECT_NEAR(length(f * Vec3d{0, 0, 1} - up), 0.0, 1e-12);
        EXPECT_NEAR(dot(cross(f.col(0), f.col(1)), f.col(2)), 1.0, 1e-12);
        EXPECT_NEAR(length(f.col(0)), 1.0, 1e-12);
        EXPECT_NEAR(dot(f.col(0), f.col(2)), 0.0, 1e-12);
    }
    const Mat3d near_ydown = panorama_frame_for_up(normalize(Vec3d{1e-4, -1, 0}));
    EXPECT_NEAR(length(near_ydown.col(1) - Vec3d{0, 0, 1}), 0.0, 1e-3);
    // -y is envmap.h's documented y-down frame.
    const Mat3d ydown = panorama_frame_for_up(Vec3d{0, -1, 0});
    EXPECT_NEAR(length(ydown.col(0) - Vec3d{1, 0, 0}), 0.0, 1e-12);
    EXPECT_NEAR(length(ydown.col(1) - Vec3d{0, 0, 1}), 0.0, 1e-12);
}

TEST(RelightLight, EstimatedUpIsTheCamerasUp) {
    // Cameras with y down = world -z, looking horizontally.
    std::vector<Camera> cams(3);
    for (std::size_t i = 0; i < cams.size(); ++i) {
        const double a = 0.7 * double(i);
        const Vec3d f{std::cos(a), std::sin(a), 0.1}, down{0, 0, -1};
        const Vec3d right = normalize(cross(down, f));
        cams[i].rotation = {{right, normalize(cross(f, right)), normalize(f)}};
    }
    EXPECT_EQ(up_axis_name(estimate_up_axis(cams)), "+z");
    // The same cameras in a world tilted by 20 deg: the up tilts with them (an axis nearest to it would not).
    const Mat3d tilt = rotation_about_axis(Vec3d{1, 0, 0}, 20 * std::numbers::pi / 180);
    std::vector<Camera> tilted = cams;
    for (Camera& c : tilted) c.rotation = c.rotation * transpose(tilt);
    EXPECT_NEAR(length(estimate_up_axis(tilted) - tilt * Vec3d{0, 0, 1}), 0.0, 1e-9);
    // COLMAP-like cameras with the identity rotation: y down = world +y, so up = -y.
    std::vector<Camera> colmap(2);
    EXPECT_EQ(up_axis_name(estimate_up_axis(colmap)), "-y");
    EXPECT_THROW(estimate_up_axis({}), Error);
}

TEST(RelightLight, FullTurnIsNoTurnAndQuarterTurnIsShRotation) {
    const ShCoeffs<double> sh = relight_test::bright_sh(11);
    for (const char* name : {"+z", "-y", "+x"}) {
        const Vec3d up = parse_up_axis(name);
        expect_sh_eq(rotate_about_up(sh, up, 0), sh);
        EXPECT_LT(max_abs_diff(rotate_about_up(sh, up, 360), sh), 1e-12) << name;
        EXPECT_LT(max_abs_diff(rotate_about_up(sh, up, 90),
                               rotate_sh(sh, rotation_about_axis(up, std::numbers::pi / 2))),
                  1e-15)
            << name;
        EXPECT_GT(max_abs_diff(rotate_about_up(sh, up, 90), sh), 1e-3) << name;
        // Four quarter turns are one full turn.
        ShCoeffs<double> r = sh;
        for (int k = 0; k < 4; ++k) r = rotate_about_up(r, up, 90);
        EXPECT_LT(max_abs_diff(r, sh), 1e-12) << name;
    }
}

TEST(RelightLight, PositiveTurnMovesTheSunCounterClockwise) {
    // A lobe towards +x, turned by +90 deg about +z, points towards +y.
    ShCoeffs<double> sun;
    double lobe[kShCount];
    cosine_lobe_sh(Vec3d{1, 0, 0}, lobe);
    for (int k = 0; k < kShCount; ++k) sun.c[k] = Vec3d{lobe[k], lobe[k], lobe[k]};
    const ShCoeffs<double> turned = rotate_about_up(sun, Vec3d{0, 0, 1}, 90);
    EXPECT_GT(eval_sh(turned, Vec3d{0, 1, 0}).x, eval_sh(turned, Vec3d{1, 0, 0}).x + 0.5);
    EXPECT_NEAR(eval_sh(turned, Vec3d{0, 1, 0}).x, eval_sh(sun, Vec3d{1, 0, 0}).x, 1e-12);
}

TEST(RelightLight, SpinAngles) {
    EXPECT_THAT(spin_angles(4, 10.0), ::testing::ElementsAre(10.0, 100.0, 190.0, 280.0));
    EXPECT_TRUE(spin_angles(0, 0.0).empty());
}

}  // namespace
}  // namespace lumigauss
