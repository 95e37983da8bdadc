// `lumigauss env`: SH -> preview panorama -> SH recovers the coefficients (EXR, PNG, every up axis, with a
// turn), the fake HDR boost of LDR panoramas, the documented convention in --help, and bad inputs (missing,
// unreadable, non-finite, a wrong SH file, a wrong preview extension) failing with the file named.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/image.h"
#include "lumigauss/shading/sh_text.h"
#include "support/run_cli.h"

namespace lumigauss {
namespace {

using testing::CommandResult;
using ::testing::HasSubstr;
using testing::run_lumigauss;
using testing::shell_quoted;
using testing::TempDir;

// A sky-like light: positive everywhere, with directional detail in every band.
ShCoeffs<double> sky_sh() {
    ShCoeffs<double> sh;
    const double v[kShCount][3] = {{1.2, 1.3, 1.5},       {0.2, 0.15, 0.1},    {0.3, 0.3, 0.35},
                                   {-0.1, 0.05, 0.1},     {0.05, -0.04, 0.02}, {-0.06, 0.03, 0.01},
                                   {-0.08, -0.07, -0.05}, {0.04, 0.02, -0.03}, {0.07, 0.05, 0.02}};
    for (int k = 0; k < kShCount; ++k) sh.c[k] = {v[k][0], v[k][1], v[k][2]};
    return sh;
}

double max_abs_diff(const ShCoeffs<double>& a, const ShCoeffs<double>& b) {
    double m = 0;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(a.c[k][c] - b.c[k][c]));
    return m;
}

CommandResult env(const std::string& args, const TempDir& tmp) {
    return run_lumigauss("env " + args, tmp);
}

TEST(CliEnv, ShToPreviewToShRoundTrips) {
    TempDir tmp("cli_env_round_trip");
    const ShCoeffs<double> sh = sky_sh();
    write_sh_text(tmp / "a.txt", sh);
    for (const char* up : {"+z", "-y", "+x"}) {
        const std::string pano = tmp / (std::string("pano") + up + ".exr");
        CommandResult r = env("--sh " + shell_quoted(tmp / "a.txt") + " --preview " + shell_quoted(pano) +
                                  " --width 256 --up " + up,
                              tmp);
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_EQ(read_image_info(pano).width, 256);
        EXPECT_EQ(read_image_info(pano).height, 128);
        r = env(shell_quoted(pano) + " -o " + shell_quoted(tmp / "b.txt") + " --up " + up, tmp);
        ASSERT_EQ(r.exit_code, 0) << r.output;
        // Midpoint quadrature of a degree-2 function with exact pixel solid angles: O(1/H^2).
        EXPECT_LT(max_abs_diff(read_sh_text(tmp / "b.txt"), sh), 2e-4) << up;
    }
    // A PNG preview (values in [0, 1], 8 bits) reads back within the quantisation.
    CommandResult r = env("--sh " + shell_quoted(tmp / "a.txt") + " --preview " +
                              shell_quoted(tmp / "p.png") + " --width 256 --up -y",
                          tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = env(shell_quoted(tmp / "p.png") + " -o " + shell_quoted(tmp / "c.txt") + " --up -y", tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_LT(max_abs_diff(read_sh_text(tmp / "c.txt"), sh), 5e-3);
}

TEST(CliEnv, RotateTurnsAboutTheUpAxis) {
    TempDir tmp("cli_env_rotate");
    write_sh_text(tmp / "a.txt", sky_sh());
    const CommandResult r = env("--sh " + shell_quoted(tmp / "a.txt") + " --preview " +
                                    shell_quoted(tmp / "p.exr") + " --width 256 --up -y --rotate 30",
                                tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_EQ(
        env(shell_quoted(tmp / "p.exr") + " -o " + shell_quoted(tmp / "b.txt") + " --up -y", tmp).exit_code,
        0);
    const ShCoeffs<double> want = rotate_about_up(sky_sh(), Vec3d{0, -1, 0}, 30);
    EXPECT_LT(max_abs_diff(read_sh_text(tmp / "b.txt"), want), 2e-4);
}

TEST(CliEnv, FakeHdrBoostsLdrPanoramas) {
    TempDir tmp("cli_env_boost");
    Image pano(64, 32, 3, 0.25f);
    for (int x = 10; x < 14; ++x) pano.at(x, 5, 0) = pano.at(x, 5, 1) = pano.at(x, 5, 2) = 1.0f;
    write_png(tmp / "pano.png", pano);
    ASSERT_EQ(env(shell_quoted(tmp / "pano.png") + " -o " + shell_quoted(tmp / "plain.txt"), tmp).exit_code,
              0);
    const CommandResult r = env(shell_quoted(tmp / "pano.png") + " -o " + shell_quoted(tmp / "boost.txt") +
                                    " --hdr-threshold 0.99 --hdr-scale 30",
                                tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("applied"));
    const ShCoeffs<double> plain = read_sh_text(tmp / "plain.txt"), boost = read_sh_text(tmp / "boost.txt");
    EXPECT_GT(boost.c[0].x, plain.c[0].x);
    // LDR is used as stored (/255, no linearisation): a constant 0.25 panorama would give 0.25 sqrt(4 pi).
    EXPECT_NEAR(plain.c[0].x, 0.25 * std::sqrt(4 * std::numbers::pi), 0.01);
}

TEST(CliEnv, HelpDocumentsTheConvention) {
    TempDir tmp("cli_env_help");
    const CommandResult r = env("--help", tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* part : {"row 0", "centre column", "Condon-Shortley", "value/255", "sRGB", "RADIANCE",
                             "--up -y: row 0 looks along -y"})
        EXPECT_THAT(r.output, HasSubstr(part));
}

TEST(CliEnv, BadInputsNameTheFile) {
    TempDir tmp("cli_env_errors");
    auto expect_failure = [&](const std::string& args, const std::string& part) {
        const CommandResult r = env(args, tmp);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_THAT(r.output, HasSubstr(part)) << args;
    };
    expect_failure(shell_quoted(tmp / "none.hdr") + " -o " + shell_quoted(tmp / "x.txt"), tmp / "none.hdr");
    std::ofstream(tmp / "fake.png") << "not a png";
    expect_failure(shell_quoted(tmp / "fake.png") + " -o " + shell_quoted(tmp / "x.txt"), tmp / "fake.png");
    Image nan_pano(16, 8, 3, 0.5f);
    nan_pano.at(3, 3, 1) = std::nanf("");
    write_exr(tmp / "nan.exr", nan_pano);
    expect_failure(shell_quoted(tmp / "nan.exr") + " -o " + shell_quoted(tmp / "x.txt"), tmp / "nan.exr");
    std::ofstream(tmp / "short.txt") << "1 2 3\n4 5 6\n";
    expect_failure("--sh " + shell_quoted(tmp / "short.txt") + " --preview " + shell_quoted(tmp / "p.exr"),
                   tmp / "short.txt");
    write_sh_text(tmp / "ok.txt", sky_sh());
    expect_failure("--sh " + shell_quoted(tmp / "ok.txt") + " --preview " + shell_quoted(tmp / "p.jpg"),
                   tmp / "p.jpg");
    expect_failure("--sh " + shell_quoted(tmp / "ok.txt"), "--preview");
    expect_failure(shell_quoted(tmp / "nan.exr") + " --sh " + shell_quoted(tmp / "ok.txt"), "not both");
    expect_failure(
        "--sh " + shell_quoted(tmp / "ok.txt") + " --preview " + shell_quoted(tmp / "p.exr") + " --up w",
        "up axis");
}

}  // namespace
}  // namespace lumigauss
