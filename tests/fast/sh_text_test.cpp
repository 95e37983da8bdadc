// SH text files (shading/sh_text.h): round trip, tolerated syntax, errors naming file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include "fast/sh_test_util.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;

// A per-test scratch directory, removed afterwards.
class ShText : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("lumigauss_sh_text_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::string write(const std::string& name, const std::string& content) const {
        const fs::path p = dir_ / name;
        std::ofstream(p) << content;
        return p.string();
    }

    // Reading `content` fails with a message that names the file and contains `what`.
    void expect_error(const std::string& content, const std::string& what) const {
        const std::string path = write("bad_sh.txt", content);
        try {
            read_sh_text(path);
            FAIL() << "expected an Error for:\n" << content;
        } catch (const Error& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(path), std::string::npos) << msg;
            EXPECT_NE(msg.find(what), std::string::npos) << msg;
        }
    }

    fs::path dir_;
};

const std::string kNineLines = "1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n";

TEST_F(ShText, RoundTrip) {
    std::mt19937_64 rng(40);
    ShCoeffs<double> sh = sh_test::random_sh(rng);
    sh.c[3].y = 1.0e-12;  // tiny and huge magnitudes survive %.9g
    sh.c[5].z = -3.5e7;
    const std::string path = (dir_ / "env_sh.txt").string();
    write_sh_text(path, sh);
    const ShCoeffs<double> back = read_sh_text(path);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.c[k][c], sh.c[k][c], 1e-8 * std::fabs(sh.c[k][c]));
    // Float coefficients round-trip exactly.
    const ShCoeffs<double> as_float = sh.cast<float>().cast<double>();
    write_sh_text(path, as_float);
    const ShCoeffs<double> back_float = read_sh_text(path);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(static_cast<float>(back_float.c[k][c]), static_cast<float>(as_float.c[k][c]));
}

TEST_F(ShText, ToleratesCommentsBlankLinesCommasAndSigns) {
    const std::string path = write("ok.txt",
                                   "# environment SH, radiance\n\n"
                                   "1 2 3   # L00\n"
                                   "  4\t5\t6\n"
                                   "+7, -8, 9e-1\n"
                                   "1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n\n# end\n");
    const ShCoeffs<double> sh = read_sh_text(path);
    EXPECT_EQ(sh.c[0].x, 1.0);
    EXPECT_EQ(sh.c[1].z, 6.0);
    EXPECT_EQ(sh.c[2].x, 7.0);
    EXPECT_EQ(sh.c[2].y, -8.0);
    EXPECT_EQ(sh.c[2].z, 0.9);
    EXPECT_EQ(sh.c[8].z, 9.0);
}

TEST_F(ShText, ReadsThePlazaFiles) {
    const fs::path path = fs::path(LUMIGAUSS_SHARED_DIR) / "data" / "plaza_mini" / "env" / "sky00_sh.txt";
    if (!fs::exists(path)) GTEST_SKIP() << "no " << path;
    const ShCoeffs<double> sh = read_sh_text(path.string());
    EXPECT_DOUBLE_EQ(sh.c[0].x, 1.80995925);
    EXPECT_DOUBLE_EQ(sh.c[8].z, 1.86203899e-01);
}

TEST_F(ShText, MissingFileIsAnError) {
    const std::string path = (dir_ / "nope.txt").string();
    try {
        read_sh_text(path);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

TEST_F(ShText, NonNumericIsAnErrorNamingTheLine) {
    expect_error("1 2 3\n4 5 6\n\n7 x 9\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n", "line 4: 'x' is not a number");
    expect_error("1 2 3\n4 5 6z\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n", "line 2: '6z'");
}

TEST_F(ShText, NonFiniteIsAnErrorNamingTheLine) {
    expect_error("1 2 3\n4 5 6\n7 8 nan\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n",
                 "line 3: 'nan' is not a finite");
    expect_error("1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 inf\n",
                 "line 9: 'inf' is not a finite");
    expect_error("1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 1e999\n", "line 9: '1e999'");
    // Finite, but its radiance is not: it gave an all-Inf preview EXR that the tool refused to read back.
    expect_error("1e308 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n",
                 "line 1: '1e308' is out of range");
}

TEST_F(ShText, WrongCountsAreErrors) {
    expect_error("1 2 3\n4 5\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n1 2 3\n4 5 6\n7 8 9\n",
                 "line 2: expected 3 numbers");
    expect_error("1 2 3 4\n", "line 1: expected 3 numbers 'R G B', found 4");
    expect_error("1 2 3\n4 5 6\n# only two\n", "expected 9 coefficient lines 'R G B', found 2");
    expect_error("", "found 0");
    expect_error(kNineLines + "\n# fine\n1 2 3\n", "line 12: more than 9 coefficient lines");
}

// 25 "#sky" rows, numbered so that a shifted or reversed row shows.
std::string sky_rows(int count) {
    std::string rows;
    for (int k = 0; k < count; ++k) rows += "#sky " + std::to_string(k) + " " + std::to_string(-k) + " 0.5\n";
    return rows;
}

// A fitted light's file carries the photo's sky residual in "#sky" rows (fit-light): they round-trip, a
// reader of the 9 rows still reads the light alone, and a file without them has no residual.
TEST_F(ShText, SkyResidualRowsRoundTripAndStayComments) {
    std::mt19937_64 rng(41);
    const ShCoeffs<double> sh = sh_test::random_sh(rng);
    Sh4Coeffs<float> sky{};
    std::uniform_real_distribution<float> value(-2.0f, 2.0f);
    for (Vec3f& c : sky.c) c = {value(rng), value(rng), value(rng)};
    sky.c[24].z = 3.0e-9f;
    const std::string path = (dir_ / "fitted_sh.txt").string();
    write_sh_text(path, sh, &sky);
    const ShTextLight back = read_sh_text_light(path);
    ASSERT_TRUE(back.sky_residual.has_value());
    for (int k = 0; k < kSh4Count; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(back.sky_residual->c[k][c], sky.c[k][c]) << k;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.sh.c[k][c], sh.c[k][c], 1e-8 * std::fabs(sh.c[k][c]));
    EXPECT_EQ(read_sh_text(path).c[4].y, back.sh.c[4].y);
    write_sh_text(path, sh);
    EXPECT_FALSE(read_sh_text_light(path).sky_residual.has_value());
    // Rows between the light's rows, indented, and a comment that only starts with the word.
    const ShTextLight mixed = read_sh_text_light(
        write("mixed.txt", "1 2 3\n" + sky_rows(25) + "  #sky01 is a comment\n" + kNineLines.substr(6)));
    ASSERT_TRUE(mixed.sky_residual.has_value());
    EXPECT_EQ(mixed.sky_residual->c[24].y, -24.0f);
    EXPECT_EQ(mixed.sh.c[8].z, 9.0);
}

// A cut or damaged block would draw a wrong sky without a word: an error naming the file and the line.
TEST_F(ShText, IncompleteSkyRowsAreErrors) {
    const auto expect_sky_error = [&](const std::string& content, const std::string& what) {
        const std::string path = write("bad_sky.txt", content);
        try {
            read_sh_text_light(path);
            FAIL() << "expected an Error for:\n" << content;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    expect_sky_error(kNineLines + sky_rows(24), "expected 25 '#sky' lines of the sky residual, found 24");
    expect_sky_error(kNineLines + sky_rows(26), "line 35: more than 25 '#sky' lines");
    expect_sky_error(kNineLines + "#sky 1 2\n", "line 10: expected '#sky R G B', found 2");
    expect_sky_error(kNineLines + "#sky 1 nan 2\n", "line 10: 'nan' is not a finite number");
}

}  // namespace
}  // namespace lumigauss
