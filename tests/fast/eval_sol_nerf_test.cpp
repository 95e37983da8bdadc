// The sol-nerf protocol (eval/sol_nerf.h) and its parts: the official SH rotations mapped onto ours (against
// the official sparse matrices), the official projection (against an independent Condon-Shortley evaluation,
// a brute-force integral, and its frame), OpenCV's resamplings (hand-computed values), the evaluation mask,
// the batched multi-light render (against one render per light), the config, and the whole protocol on a
// synthetic NeRF-OSR scene whose photos were rendered at known angles.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "fast/relight_test_util.h"
#include "fast/sh_test_util.h"
#include "lumigauss/eval/multi_light_render.h"
#include "lumigauss/eval/official_sh_projection.h"
#include "lumigauss/eval/official_sh_rotation.h"
#include "lumigauss/eval/opencv_resize.h"
#include "lumigauss/eval/sol_nerf.h"
#include "lumigauss/eval/sol_nerf_config.h"
#include "lumigauss/eval/sol_nerf_report.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/util/error.h"
#include "support/sol_nerf_scene.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::TempDir;
constexpr double kPi = std::numbers::pi;

// ---- The official rotation matrices
// ------------------------------------------------------------------------

using Mat9 = std::array<std::array<double, kShCount>, kShCount>;

Mat9 mat9_product(const Mat9& a, const Mat9& b) {
    Mat9 r{};
    for (int i = 0; i < kShCount; ++i)
        for (int j = 0; j < kShCount; ++j)
            for (int k = 0; k < kShCount; ++k) r[i][j] += a[i][k] * b[k][j];
    return r;
}

// NeRF-OSR's rot_z, entry by entry as research/lumigauss_official.md 6 lists it.
Mat9 official_rot_z_matrix(double a) {
    Mat9 m{};
    m[0][0] = m[2][2] = m[6][6] = 1;
    m[1][1] = std::cos(a), m[1][3] = std::sin(a), m[3][1] = -std::sin(a), m[3][3] = std::cos(a);
    m[4][4] = std::cos(2 * a), m[4][8] = std::sin(2 * a), m[8][4] = -std::sin(2 * a),
    m[8][8] = std::cos(2 * a);
    m[5][5] = std::cos(a), m[5][7] = std::sin(a), m[7][5] = -std::sin(a), m[7][7] = std::cos(a);
    return m;
}

// Its fixed quarter turns X+90 (sign +1) and X-90 (sign -1).
Mat9 official_x90_matrix(double sign) {
    const double s = std::sqrt(3.0) / 2;
    Mat9 m{};
    m[0][0] = 1, m[1][2] = -sign, m[2][1] = sign, m[3][3] = 1, m[4][7] = -sign, m[5][5] = -1;
    m[6][6] = -0.5, m[6][8] = -s, m[7][4] = sign, m[8][6] = -s, m[8][8] = 0.5;
    return m;
}

Mat9 official_rot_y_matrix(double a) {
    return mat9_product(official_x90_matrix(1),
                        mat9_product(official_rot_z_matrix(a), official_x90_matrix(-1)));
}

Mat9 official_rot_x_matrix(double a) {
    return mat9_product(official_rot_y_matrix(kPi / 2),
                        mat9_product(official_rot_z_matrix(a), official_rot_y_matrix(-kPi / 2)));
}

void expect_same_matrix(const Mat9& official, const Mat3d& ours, const char* what, double angle) {
    const ShRotation r = sh_rotation(ours);
    for (int i = 0; i < kShCount; ++i)
        for (int j = 0; j < kShCount; ++j)
            EXPECT_NEAR(r.m[i][j], official[i][j], 1e-12)
                << what << "(" << angle << ") entry " << i << "," << j;
}

TEST(SolNerfRotation, OfficialMatricesAreTheseActiveRotations) {
    for (double a : {0.3, -1.1, 2.5, kPi / 2, -kPi / 2, 4.0}) {
        expect_same_matrix(official_rot_z_matrix(a), official_rot_z(a), "rot_z", a);
        expect_same_matrix(official_rot_y_matrix(a), official_rot_y(a), "rot_y", a);
        expect_same_matrix(official_rot_x_matrix(a), official_rot_x(a), "rot_x", a);
    }
    // The composed protocol rotation equals the product of the official matrices in the official order.
    const double x0 = -95 * kPi / 180, y0 = 0.2, z0 = -0.3, b = 1.3;
    const Mat9 official =
        mat9_product(official_rot_y_matrix(b),
                     mat9_product(official_rot_y_matrix(y0),
                                  mat9_product(official_rot_x_matrix(x0), official_rot_z_matrix(z0))));
    expect_same_matrix(official, official_environment_rotation(x0, y0, z0, b), "composed", b);
}

TEST(SolNerfRotation, RotatedCoefficientsAreTheFunctionAtRotatedDirections) {
    std::mt19937_64 rng(51);
    for (int trial = 0; trial < 10; ++trial) {
        const ShCoeffs<double> sh = sh_test::random_sh(rng);
        const double a = sh_test::uniform(rng, -kPi, kPi);
        const Mat3d r = official_environment_rotation(-kPi / 2, 0, 0, a);
        const ShCoeffs<double> rotated = rotate_sh(sh, r);
        for (int i = 0; i < 20; ++i) {
            const Vec3d w = sh_test::random_unit(rng);
            const Vec3d want = eval_sh(sh, transpose(r) * w), got = eval_sh(rotated, w);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-10);
        }
    }
    // rot_x(-90 deg) takes the panorama's zenith to world -y (COLMAP up); rot_y(a) turns +x towards +z.
    const Vec3d up = official_rot_x(-kPi / 2) * Vec3d{0, 0, 1};
    EXPECT_NEAR(up.y, -1.0, 1e-15);
    const Vec3d turned = official_rot_y(0.1) * Vec3d{1, 0, 0};
    EXPECT_GT(turned.z, 0.09);
}

// ---- The official projection ------------------------------------------------------------------------------

// Associated Legendre P_l^m(x) with the Condon-Shortley phase, l <= 2 (closed forms).
double legendre_cs(int l, int m, double x) {
    const double s = std::sqrt(std::max(0.0, 1 - x * x));
    if (l == 0) return 1;
    if (l == 1) return m == 0 ? x : -s;
    if (m == 0) return 0.5 * (3 * x * x - 1);
    return m == 1 ? -3 * x * s : 3 * s * s;
}

double factorial(int n) {
    return n <= 1 ? 1.0 : n * factorial(n - 1);
}

// Chalmers' real SH in spherical coordinates, written from its definition (not from our basis).
double chalmers_sh(int l, int m, double theta, double phi) {
    const int am = std::abs(m);
    const double k = std::sqrt((2 * l + 1) * factorial(l - am) / (4 * kPi * factorial(l + am)));
    const double p = legendre_cs(l, am, std::cos(theta));
    if (m == 0) return k * p;
    return std::sqrt(2.0) * k * p * (m > 0 ? std::cos(m * phi) : std::sin(am * phi));
}

Image random_panorama(int width, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    Image pano(width, width / 2, 3);
    for (float& v : pano.pixels) v = float(sh_test::uniform(rng, 0.0, 1.0));
    return pano;
}

TEST(SolNerfProjection, MatchesTheCondonShortleyDefinition) {
    const Image pano = random_panorama(64, 3);
    const int w = pano.width, h = pano.height;
    ShCoeffs<double> want;
    for (int row = 0; row < h; ++row)
        for (int col = 0; col < w; ++col) {
            const double theta = kPi * row / h, phi = 2 * kPi * col / w;
            const double ts = kPi * (1 - (row + 0.5) / h);
            const double d_omega =
                (2 * kPi / w) * (std::cos(ts - kPi / (2 * h)) - std::cos(ts + kPi / (2 * h)));
            for (int l = 0; l <= 2; ++l)
                for (int m = -l; m <= l; ++m)
                    for (int c = 0; c < 3; ++c)
                        want.c[l * l + l + m][c] +=
                            pano.at(col, row, c) * chalmers_sh(l, m, theta, phi) * d_omega;
        }
    const ShCoeffs<double> got = official_project_panorama(pano);
    EXPECT_LT(sh_test::max_abs_diff(got, want), 1e-12);
}

TEST(SolNerfProjection, MatchesABruteForceIntegralInItsFrame) {
    // A smooth light f(d) sampled at the official pixel directions; its SH by a dense equal-area quadrature
    // of f(d) Y(d) over the sphere. The official sampling at pixel corners costs O(1/H) accuracy.
    const Vec3d s = normalize(Vec3d{0.3, -0.5, 0.8});
    auto f = [&](Vec3d d) { return std::exp(2.0 * dot(d, s)); };
    const int w = 800;
    Image pano(w, w / 2, 1);
    for (int row = 0; row < w / 2; ++row)
        for (int col = 0; col < w; ++col)
            pano.at(col, row, 0) = float(f(official_panorama_direction(row, col, w)));
    const ShCoeffs<double> got = official_project_panorama(pano);
    double want[kShCount]{};
    const int n = 400000;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1 - z * z), phi = golden * i;
        const Vec3d d{r * std::cos(phi), r * std::sin(phi), z};
        double y[kShCount];
        sh_basis(d, y);
        for (int k = 0; k < kShCount; ++k) want[k] += f(d) * y[k] * 4 * kPi / n;
    }
    for (int k = 0; k < kShCount; ++k) {
        EXPECT_NEAR(got.c[k].x, want[k], 0.01 * std::abs(want[0])) << "k=" << k;
        EXPECT_EQ(got.c[k].x, got.c[k].z) << "a gray panorama gives equal channels";
    }
}

// The direction of the largest radiance of an SH light (coarse search over a Fibonacci sphere).
Vec3d brightest_direction(const ShCoeffs<double>& sh) {
    Vec3d best{};
    double best_value = -1e300;
    const int n = 20000;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1 - z * z), phi = golden * i;
        const Vec3d d{r * std::cos(phi), r * std::sin(phi), z};
        if (eval_sh(sh, d).x > best_value) best_value = eval_sh(sh, d).x, best = d;
    }
    return best;
}

// A panorama black but for a bright block of rows [r0, r1) x columns [c0, c1).
Image bright_block(int w, int r0, int r1, int c0, int c1) {
    Image pano(w, w / 2, 3);
    for (int y = r0; y < r1; ++y)
        for (int x = c0; x < c1; ++x)
            for (int c = 0; c < 3; ++c) pano.at(x, y, c) = 1.0f;
    return pano;
}

TEST(SolNerfProjection, FrameCorrespondence) {
    const int w = 360, h = 180;
    // Top rows: the maximum is at +z.
    EXPECT_GT(brightest_direction(official_project_panorama(bright_block(w, 0, 3, 0, w))).z, 0.99);
    // The horizon at the centre column (phi = pi): +x.
    EXPECT_GT(brightest_direction(
                  official_project_panorama(bright_block(w, h / 2 - 3, h / 2 + 3, w / 2 - 3, w / 2 + 3)))
                  .x,
              0.97);
    // A quarter width from the left (phi = pi/2): -y, the mirror image of `lumigauss env`'s +y there.
    EXPECT_LT(brightest_direction(
                  official_project_panorama(bright_block(w, h / 2 - 3, h / 2 + 3, w / 4 - 3, w / 4 + 3)))
                  .y,
              -0.97);
    // After the alignment rot_x(-90 deg), the top rows light world -y (up in COLMAP).
    const ShCoeffs<double> top = official_project_panorama(bright_block(w, 0, 3, 0, w));
    EXPECT_LT(brightest_direction(rotate_sh(top, official_rot_x(-kPi / 2))).y, -0.99);
}

TEST(SolNerfProjection, ResizesWidePanoramasAndRejectsOthers) {
    // A constant panorama wider than 1000: resized (bicubic keeps constants) then integrated: L00 = c sqrt(4
    // pi) (the solid angles sum to 4 pi), no azimuthal term; but the official directions sit at the pixels'
    // top corners (theta = pi row / H) while the weights are the pixels' own, which tilts the light up a
    // little: small positive zonal terms (L10, L20), an artefact of the official code, reproduced.
    const Image wide(1200, 600, 3, 0.5f);
    const ShCoeffs<double> sh = official_project_panorama(wide);
    EXPECT_NEAR(sh.c[0].x, 0.5 * std::sqrt(4 * kPi), 1e-9);
    for (int k : {1, 3, 4, 5, 7, 8}) EXPECT_NEAR(sh.c[k].y, 0.0, 1e-9) << k;
    EXPECT_GT(sh.c[2].y, 0.0);
    EXPECT_LT(sh.c[2].y, 0.01 * sh.c[0].y);
    EXPECT_THROW(official_project_panorama(Image(100, 40, 3, 0.5f)), Error);  // not 2:1
    Image bad = random_panorama(32, 1);
    bad.at(3, 2, 1) = std::nanf("");
    EXPECT_THROW(official_project_panorama(bad), Error);
}

TEST(SolNerfProjection, FileErrorsNameTheFile) {
    TempDir tmp("sol_projection_errors");
    auto expect_error = [](auto&& f, const std::string& part) {
        try {
            f();
            FAIL() << "expected an error naming " << part;
        } catch (const Error& e) {
            EXPECT_THAT(e.what(), HasSubstr(part));
        }
    };
    expect_error([&] { official_environment_sh(tmp / "none.jpg", 0.99, 10); }, tmp / "none.jpg");
    write_png(tmp / "narrow.png", Image(40, 30, 3, 0.2f));
    expect_error([&] { official_environment_sh(tmp / "narrow.png", 0.99, 10); }, tmp / "narrow.png");
    std::ofstream(tmp / "text.jpg") << "not an image";
    expect_error([&] { official_environment_sh(tmp / "text.jpg", 0.99, 10); }, tmp / "text.jpg");
    // The fake HDR multiplies values above the threshold only, and counts them.
    Image pano(8, 4, 3, 0.5f);
    pano.at(1, 1, 0) = 1.0f;
    write_png(tmp / "sun.png", pano);
    const OfficialEnvironment boosted = official_environment_sh(tmp / "sun.png", 0.99, 10);
    EXPECT_EQ(boosted.boosted, 1u);
    const OfficialEnvironment plain = official_environment_sh(tmp / "sun.png", 0.99, 1);
    EXPECT_GT(boosted.sh.c[0].x, plain.sh.c[0].x);
    EXPECT_DOUBLE_EQ(boosted.sh.c[0].y, plain.sh.c[0].y);
}

// ---- OpenCV resampling ------------------------------------------------------------------------------------

Image row_image(std::vector<float> values) {
    Image im(int(values.size()), 1, 1);
    im.pixels = std::move(values);
    return im;
}

TEST(SolNerfResize, OpenCvCubicAndLinearKnownValues) {
    // 4 -> 2 pixels: sources at 0.5 and 2.5, Keys A = -0.75 weights (-3/32, 19/32, 19/32, -3/32), replicated
    // edge.
    const Image cubic = resize_cubic_opencv(row_image({0, 1, 2, 3}), 2, 1);
    EXPECT_NEAR(cubic.pixels[0], 0.40625, 1e-7);
    EXPECT_NEAR(cubic.pixels[1], 2.59375, 1e-7);
    const Image linear = resize_linear_opencv(row_image({0, 1, 2, 3}), 2, 1);
    EXPECT_NEAR(linear.pixels[0], 0.5, 1e-7);
    EXPECT_NEAR(linear.pixels[1], 2.5, 1e-7);
    // 2 -> 4: positions -0.25, 0.25, 0.75, 1.25; outside the centres the edge pixel alone.
    const Image up = resize_linear_opencv(row_image({0, 4}), 4, 1);
    EXPECT_EQ(up.pixels, (std::vector<float>{0, 1, 3, 4}));
    // Same size: unchanged; constants stay constant; columns resample like rows.
    const Image same = resize_cubic_opencv(random_panorama(16, 4), 16, 8);
    EXPECT_EQ(same.pixels, random_panorama(16, 4).pixels);
    for (float v : resize_cubic_opencv(Image(7, 5, 2, 0.25f), 3, 11).pixels) EXPECT_NEAR(v, 0.25f, 1e-6);
    Image column(1, 4, 1);
    column.pixels = {0, 1, 2, 3};
    EXPECT_NEAR(resize_cubic_opencv(column, 1, 2).pixels[0], 0.40625, 1e-7);
}

// ---- Mask, angles, best index, views
// -----------------------------------------------------------------------

std::size_t ones(const Image& mask) {
    return mask_pixels(mask);
}

TEST(SolNerfMask, ResizedErodedAndOnlyFullCoverageCounts) {
    Image m(20, 16, 1, 1.0f);
    m.at(10, 8, 0) = 0.0f;
    EXPECT_EQ(ones(sol_nerf_eval_mask(m, 20, 16)), 20u * 16u - 25u);  // one hole grows to 5x5
    m.at(10, 8, 0) = 254.0f / 255.0f;                                 // not exactly 255: a hole too
    EXPECT_EQ(ones(sol_nerf_eval_mask(m, 20, 16)), 20u * 16u - 25u);
    m.at(10, 8, 0) = 1.0f;
    m.at(0, 0, 0) = 0.0f;  // at the corner the erosion ignores the outside: 3x3 lost
    EXPECT_EQ(ones(sol_nerf_eval_mask(m, 20, 16)), 20u * 16u - 9u);
    // Left half 0 at 10x8, resized to 20x16: output columns >= 11 interpolate two 255s; erosion drops 2 more.
    Image half(10, 8, 1, 1.0f);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 5; ++x) half.at(x, y, 0) = 0.0f;
    EXPECT_EQ(ones(sol_nerf_eval_mask(half, 20, 16)), 7u * 16u);
}

TEST(SolNerfSearch, AnglesBestIndexAndViewNames) {
    const std::vector<double> a = sol_nerf_angles(-0.1 * kPi, 0.4 * kPi, 51);
    ASSERT_EQ(a.size(), 51u);
    EXPECT_EQ(a.front(), -0.1 * kPi);
    EXPECT_EQ(a.back(), 0.4 * kPi);
    EXPECT_NEAR(a[25], 0.15 * kPi, 1e-15);
    EXPECT_NEAR(a[1] - a[0], 0.01 * kPi, 1e-15);
    EXPECT_EQ(sol_nerf_angles(0.5, 2.0, 1), (std::vector<double>{0.5}));
    EXPECT_EQ(first_best_index({1, 3, 3, 2}), 1u);
    EXPECT_EQ(first_best_index({std::nan(""), 2, std::nan(""), 1}), 1u);
    EXPECT_THROW(first_best_index({}), Error);

    Dataset d;
    d.views.resize(3);
    d.views[0].name = "a.JPG", d.views[1].name = "b.png", d.views[2].name = "b.jpg";
    EXPECT_EQ(find_sol_nerf_view(d, "a.JPG"), &d.views[0]);
    EXPECT_EQ(find_sol_nerf_view(d, "a.png"), &d.views[0]);  // same stem
    EXPECT_EQ(find_sol_nerf_view(d, "b.JPG"), nullptr);      // two with that stem
    EXPECT_EQ(find_sol_nerf_view(d, "b.png"), &d.views[1]);  // the exact name wins
    EXPECT_EQ(find_sol_nerf_view(d, "c.png"), nullptr);
}

// ---- The batched multi-light render
// --------------------------------------------------------------------------

TEST(SolNerfMultiLight, EqualsOneRenderPerLight) {
    Camera cam;
    cam.width = 40, cam.height = 30, cam.fx = cam.fy = 36, cam.cx = 20, cam.cy = 15;
    const GaussianModel model = relight_test::random_model(cam, 11, 80);
    std::vector<ShCoeffs<float>> envs;
    for (int k = 0; k < 7; ++k) envs.push_back(relight_test::bright_sh(100 + std::uint64_t(k)).cast<float>());
    MultiLightRenderer renderer(model);
    const std::vector<Image> renders = renderer.render_shadowed(cam, envs);
    ASSERT_EQ(renders.size(), envs.size());
    for (std::size_t k = 0; k < envs.size(); ++k) {
        const std::vector<float> want =
            render_with_environment(model, cam, envs[k], ShadingMode::Shadowed).color;
        ASSERT_EQ(renders[k].pixels.size(), want.size());
        double max_diff = 0, max_value = 0;
        for (std::size_t i = 0; i < want.size(); ++i) {
            max_diff = std::max(max_diff, double(std::abs(renders[k].pixels[i] - want[i])));
            max_value = std::max(max_value, double(want[i]));
        }
        EXPECT_LT(max_diff, 1e-6 * std::max(1.0, max_value)) << "light " << k;
        EXPECT_GT(max_value, 0.05) << "the render is not black";
    }
}

// ---- Config
// -------------------------------------------------------------------------------------------------

std::string repo_root() {
    return fs::path(__FILE__).parent_path().parent_path().parent_path().string();
}

TEST(SolNerfConfig, ShippedConfigsHoldTheOfficialValues) {
    const SolNerfConfig lk2 = load_sol_nerf_config(repo_root() + "/configs/sol_nerf/lk2.json");
    ASSERT_EQ(lk2.images.size(), 5u);
    EXPECT_EQ(lk2.angles, 51);
    EXPECT_EQ(lk2.images[0].name, "01-08_07_30_IMG_6710.JPG");
    EXPECT_EQ(lk2.images[0].env_map, "ENV_MAP_CC/01-08_07_30/20210801_082411.jpg");
    EXPECT_NEAR(lk2.images[0].y_min, -0.1 * kPi, 1e-15);
    EXPECT_NEAR(lk2.images[0].y_max, 0.4 * kPi, 1e-15);
    EXPECT_EQ(lk2.images[0].rotation_deg[0], -90);
    EXPECT_EQ(lk2.images[0].hdr_threshold, 0.999);
    EXPECT_EQ(lk2.images[0].hdr_scale, 10);
    const SolNerfConfig st = load_sol_nerf_config(repo_root() + "/configs/sol_nerf/st.json");
    ASSERT_EQ(st.images.size(), 5u);
    EXPECT_EQ(st.images[4].rotation_deg[0], -95);
    EXPECT_EQ(st.images[4].hdr_scale, 30);
    const SolNerfConfig lwp = load_sol_nerf_config(repo_root() + "/configs/sol_nerf/lwp.json");
    ASSERT_EQ(lwp.images.size(), 5u);
    EXPECT_EQ(lwp.images[2].hdr_threshold, 0.99);
    EXPECT_EQ(lwp.images[2].hdr_scale, 20);
}

void expect_config_error(const std::string& json, const std::vector<std::string>& parts) {
    TempDir tmp("sol_config_error");
    const std::string path = tmp / "bad.json";
    std::ofstream(path) << json;
    try {
        load_sol_nerf_config(path);
        FAIL() << "expected an error for " << json;
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr(path));
        for (const std::string& p : parts) EXPECT_THAT(e.what(), HasSubstr(p)) << json;
    }
}

TEST(SolNerfConfig, DefaultsOverridesAndErrors) {
    const nlohmann::json j = nlohmann::json::parse(R"({
        "_note": "comments are keys starting with _",
        "defaults": {"rotation_deg": {"x": -90}, "hdr_threshold": 0.99, "hdr_scale": 20, "y_range_pi": [0, 1]},
        "images": [{"name": "a.jpg", "env_map": "e.jpg"},
                   {"name": "b.jpg", "env_map": "f.jpg", "mask": "m.png", "hdr_scale": 5, "y_range_pi": [-1, 0.5],
                    "rotation_deg": {"y": 10}}]})");
    const SolNerfConfig c = parse_sol_nerf_config(j, "cfg.json");
    ASSERT_EQ(c.images.size(), 2u);
    EXPECT_EQ(c.angles, 51);
    EXPECT_EQ(c.images[0].rotation_deg[0], -90);
    EXPECT_TRUE(c.images[0].mask.empty());
    EXPECT_EQ(c.images[0].hdr_scale, 20);
    EXPECT_EQ(c.images[1].hdr_scale, 5);
    EXPECT_EQ(c.images[1].mask, "m.png");
    EXPECT_EQ(c.images[1].rotation_deg[0], 0);  // an image's own rotation replaces the default's
    EXPECT_EQ(c.images[1].rotation_deg[1], 10);
    EXPECT_NEAR(c.images[1].y_min, -kPi, 1e-15);

    expect_config_error("{not json", {"not valid JSON"});
    expect_config_error(R"({"images": []})", {"images"});
    expect_config_error(
        R"({"images": [{"name": "a.jpg", "env_map": "e.jpg", "hdr_threshold": 0.9, "hdr_scale": 2}]})",
        {"a.jpg", "y_range_pi"});
    expect_config_error(
        R"({"images": [{"name": "a.jpg", "env_map": "e.jpg", "hdr_threshold": 0.9, "hdr_scale": 2, "y_range": [0, 1]}]})",
        {"unknown key", "y_range"});
    expect_config_error(
        R"({"images": [{"name": "a.jpg", "y_range_pi": [0, 1], "hdr_threshold": 0.9, "hdr_scale": 2}]})",
        {"a.jpg", "env_map"});
    expect_config_error(
        R"({"images": [{"name": "a.jpg", "env_map": "e.jpg", "hdr_threshold": 0.9, "hdr_scale": 0, "y_range_pi": [0, 1]}]})",
        {"hdr_scale", "positive"});
    expect_config_error(R"({"angles": 0, "images": [{"name": "a.jpg"}]})", {"angles"});
    TempDir tmp("sol_config_missing");
    try {
        load_sol_nerf_config(tmp / "nowhere.json");
        FAIL();
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr(tmp / "nowhere.json"));
    }
}

TEST(SolNerfConfig, PathsAndShippedLookup) {
    TempDir tmp("sol_config_paths");
    fs::create_directories(tmp / "scene/final/ENV_MAP_CC/s");
    std::ofstream(tmp / "scene/final/ENV_MAP_CC/s/e.jpg") << "x";
    std::vector<std::string> tried;
    EXPECT_EQ(resolve_sol_nerf_path("ENV_MAP_CC/s/e.jpg", "", tmp / "scene", tried),
              (fs::path(tmp / "scene") / "final" / "ENV_MAP_CC/s/e.jpg").string());
    EXPECT_EQ(tried.size(), 2u);
    EXPECT_EQ(resolve_sol_nerf_path("s/e.jpg", tmp / "scene/final/ENV_MAP_CC", "unused", tried),
              (fs::path(tmp / "scene/final/ENV_MAP_CC") / "s/e.jpg").string());
    EXPECT_FALSE(resolve_sol_nerf_path("x.jpg", tmp / "scene", "", tried));
    EXPECT_EQ(tried, (std::vector<std::string>{(fs::path(tmp / "scene") / "x.jpg").string()}));
    EXPECT_EQ(guess_sol_nerf_scene("/data/lk2_colmap/undistorted"), "lk2");
    EXPECT_EQ(guess_sol_nerf_scene("data/st"), "st");
    EXPECT_EQ(guess_sol_nerf_scene("data/test/stuff"), "");
    EXPECT_EQ(find_shipped_sol_nerf_config("lwp", {tmp.str(), repo_root() + "/configs/sol_nerf"}),
              repo_root() + "/configs/sol_nerf/lwp.json");
    EXPECT_FALSE(find_shipped_sol_nerf_config("lwp", {tmp.str()}));
}

// ---- The protocol on a synthetic NeRF-OSR scene
// ----------------------------------------------------------------

struct SolScene {
    TempDir dir{"sol_nerf_scene"};
    GaussianModel model = testing::street_model();
    testing::SolNerfTestScene scene = testing::write_sol_nerf_test_scene(dir.str(), model);
    SolNerfOptions options() const {
        SolNerfOptions o;
        o.roots = {scene.scene, "", scene.mask_root};
        return o;
    }
};

const SolScene& sol_scene() {
    static SolScene s;
    return s;
}

TEST(SolNerfProtocol, RecoversTheAngleThePhotosWereRenderedAt) {
    const SolScene& s = sol_scene();
    const Dataset scene = load_dataset(s.scene.scene);
    const SolNerfConfig config = load_sol_nerf_config(s.scene.config);
    const SolNerfResult r = evaluate_sol_nerf(s.model, scene, config, s.options());
    ASSERT_EQ(r.images.size(), 2u);
    for (std::size_t i = 0; i < r.images.size(); ++i) {
        const SolNerfImageResult& im = r.images[i];
        const testing::SolNerfTestImage& truth = s.scene.images[i];
        EXPECT_EQ(im.view_name, truth.stem + ".png");
        EXPECT_EQ(im.best_index, truth.true_index) << im.config.name;
        ASSERT_EQ(im.search_psnr.size(), 51u);
        // 16-bit photos of the same model: the PSNR reaches its 60 dB cap at the true angle, and one search
        // step (1/50 of the range, 3.6 degrees) away the walls lit by the sun's SH lobe already differ
        // (measured 53 dB).
        EXPECT_GT(im.shadowed.psnr, 59.0);
        EXPECT_GT(im.shadowed.ssim, 0.9999);
        EXPECT_LT(im.search_psnr[truth.true_index - 1], im.search_psnr[truth.true_index] - 3.0);
        EXPECT_LT(im.search_psnr[truth.true_index + 1], im.search_psnr[truth.true_index] - 3.0);
        // Cosine-lobe transfer: the unshadowed render is the same picture.
        EXPECT_GT(im.unshadowed.psnr, 50.0);
        EXPECT_GT(im.boosted_values, 0u);
        EXPECT_FALSE(im.best_at_range_edge());
        EXPECT_EQ(im.panels.truth.width, 64);
        EXPECT_FALSE(im.panels.albedo.empty());
    }
    // The first image's configured mask (half size, an 8x6 hole) vs the second's scene mask (all ones).
    EXPECT_LT(r.images[0].mask_pixels, 64u * 48u - 16u * 12u);
    EXPECT_EQ(r.images[1].mask_pixels, 64u * 48u);
    EXPECT_FALSE(r.images[0].mask_path.empty());
    EXPECT_TRUE(r.images[1].mask_path.empty());
    EXPECT_NEAR(r.mean_shadowed.psnr, (r.images[0].shadowed.psnr + r.images[1].shadowed.psnr) / 2, 1e-9);
    // The report's JSON has every key.
    const nlohmann::ordered_json j = sol_nerf_metrics_json(r, {"run", s.scene.scene});
    EXPECT_EQ(j["protocol"], "sol-nerf");
    EXPECT_EQ(j["images"][0]["best_index"], s.scene.images[0].true_index);
    EXPECT_EQ(j["images"][0]["search_psnr"].size(), 51u);
    EXPECT_EQ(j["images"][1]["mask_file"], nullptr);
    EXPECT_TRUE(j["mean"]["shadowed"].contains("ssim"));
}

TEST(SolNerfProtocol, ErrorsNameTheFile) {
    const SolScene& s = sol_scene();
    const Dataset scene = load_dataset(s.scene.scene);
    const SolNerfConfig good = load_sol_nerf_config(s.scene.config);
    auto expect_error = [&](const SolNerfConfig& c, const SolNerfOptions& o,
                            const std::vector<std::string>& parts) {
        try {
            evaluate_sol_nerf(s.model, scene, c, o);
            FAIL() << "expected an error";
        } catch (const Error& e) {
            for (const std::string& p : parts) EXPECT_THAT(e.what(), HasSubstr(p));
        }
    };
    SolNerfConfig c = good;
    c.images[1].name = "09-09_09_09_IMG_9999.JPG";
    expect_error(c, s.options(), {s.scene.config, "09-09_09_09_IMG_9999.JPG"});
    c = good;
    c.images[0].env_map = "ENV_MAP_CC/nowhere/x.jpg";
    expect_error(c, s.options(), {"ENV_MAP_CC/nowhere/x.jpg", "missing", "--env-root"});
    c = good;
    c.images[0].mask = "absent.png";
    expect_error(c, s.options(), {(fs::path(s.scene.mask_root) / "absent.png").string(), "--mask-root"});
    // An all-black mask leaves nothing to score.
    TempDir tmp("sol_empty_mask");
    write_png(tmp / "black.png", Image(32, 24, 1, 0.0f));
    c = good;
    c.images[0].mask = tmp / "black.png";
    expect_error(c, s.options(), {tmp / "black.png", "empty"});
}

}  // namespace
}  // namespace lumigauss
