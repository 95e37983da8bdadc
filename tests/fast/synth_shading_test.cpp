// The ground-truth lighting written for evaluation agrees with the photos: on surfaces the sun reaches, the
// photo's radiance divided by albedo/pi is the irradiance of the sky SH (exact, Ramamoorthi-Hanrahan) plus
// the sun's; the written env SH (sky + sun disc) gives it up to the order-2 truncation of the sun's cosine
// lobe; the env maps project back onto the env SH; sky pixels show the sky SH.
#include <gtest/gtest.h>

#include <cmath>

#include "lumigauss/io/image.h"
#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/synth/camera_paths.h"
#include "lumigauss/synth/ray_tracer.h"
#include "lumigauss/synth/sky.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;

const std::string& tiny_dataset() {
    static TempDir dir("synth_shading");
    static const std::string root = [] {
        synth::generate_synthetic_scene(synth_test::tiny_options(dir.str()));
        return dir.str();
    }();
    return root;
}

Vec3d json_vec(const nlohmann::json& j) {
    return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

ShCoeffs<double> json_sh(const nlohmann::json& rows) {
    ShCoeffs<double> sh;
    for (int k = 0; k < kShCount; ++k) sh.c[k] = json_vec(rows[std::size_t(k)]);
    return sh;
}

Vec3d pixel(const Image& im, int x, int y) {
    return {im.at(x, y, 0), im.at(x, y, 1), im.at(x, y, 2)};
}

TEST(SynthShading, TracedShadingMatchesSkyShIrradianceOnSunlitSurfaces) {
    const std::string root = tiny_dataset();
    const auto meta = synth_test::read_json(root + "/meta.json");
    std::map<std::string, nlohmann::json> conditions;
    for (const auto& c : meta["conditions"]) conditions[c["id"]] = c;
    int checked = 0;
    double worst_env_error = 0;
    for (const auto& im : meta["images"]) {
        const std::string name = im["name"];
        const auto& cond = conditions.at(im["condition"]);
        const ShCoeffs<double> sky = json_sh(cond["sky_sh"]);
        const ShCoeffs<double> env = read_sh_text(root + "/" + cond["sh"].get<std::string>());
        const Vec3d sun = json_vec(cond["sun_dir_world"]), power = json_vec(cond["sun_power_rgb"]);
        const double exposure = im["exposure"];
        const Image photo = read_image(root + "/images/" + name),
                    albedo = read_image(root + "/gt/albedo/" + name);
        const Image normal = read_image(root + "/gt/normal/" + name),
                    mask = read_image(root + "/gt/mask/" + name);
        const Image lit = read_image(root + "/gt/sun_visibility/" + name);
        const Image transient = read_image(root + "/gt/transient/" + name);
        for (int y = 0; y < photo.height; ++y)
            for (int x = 0; x < photo.width; ++x) {
                if (mask.at(x, y, 0) < 1 || lit.at(x, y, 0) < 1 || transient.at(x, y, 0) > 0) continue;
                const Vec3d n = 2.0 * pixel(normal, x, y) - Vec3d{1, 1, 1};
                if (std::abs(length(n) - 1) > 1e-4) continue;  // samples on different faces
                const Vec3d e_true = irradiance(sky, n) + std::max(0.0, dot(n, sun)) * power;
                for (int c = 0; c < 3; ++c) {
                    const double code = photo.at(x, y, c) * 255.0, rho = albedo.at(x, y, c);
                    if (code < 60 || code > 250 || rho < 0.08) continue;
                    // Radiance from the 8-bit value; half a code of quantisation bounds the error.
                    const double radiance = srgb_to_linear(photo.at(x, y, c)) / exposure;
                    const double e_photo = std::numbers::pi * radiance / rho;
                    const double hi = srgb_to_linear(float((code + 0.5) / 255)),
                                 lo = srgb_to_linear(float((code - 0.5) / 255));
                    const double tolerance = 0.5 * (hi - lo) / srgb_to_linear(float(code / 255)) + 2e-4;
                    EXPECT_NEAR(e_photo / e_true[c], 1.0, tolerance) << name << " pixel " << x << "," << y;
                    ++checked;
                }
                // The env SH (sun as its SH projection) differs only by the order-2 truncation of the sun's
                // cosine lobe: at most 0.094 * sun power (at grazing incidence).
                const Vec3d e_env = irradiance(env, n);
                for (int c = 0; c < 3; ++c) {
                    EXPECT_LE(std::abs(e_env[c] - e_true[c]), 0.095 * power[c] + 1e-6) << name;
                    worst_env_error = std::max(worst_env_error, std::abs(e_env[c] - e_true[c]) / power[c]);
                }
            }
    }
    EXPECT_GT(checked, 500);
    EXPECT_GT(worst_env_error, 0.0);
}

// The equirectangular map is the same environment as the SH file (plaza's projection formula).
TEST(SynthShading, EnvMapsProjectOntoTheirSh) {
    const std::string root = tiny_dataset();
    const auto meta = synth_test::read_json(root + "/meta.json");
    for (const auto& c : meta["conditions"]) {
        const Image pano = read_image(root + "/" + c["env_exr"].get<std::string>());
        ASSERT_EQ(pano.width, 128);
        ASSERT_EQ(pano.height, 64);
        const ShCoeffs<double> from_map = project_panorama_to_sh(pano);
        const ShCoeffs<double> sh = read_sh_text(root + "/" + c["sh"].get<std::string>());
        double largest = 0, diff = 0;
        for (int k = 0; k < kShCount; ++k)
            for (int ch = 0; ch < 3; ++ch) {
                largest = std::max(largest, std::abs(sh.c[k][ch]));
                diff = std::max(diff, std::abs(sh.c[k][ch] - from_map.c[k][ch]));
            }
        EXPECT_LT(diff, 2e-3 * largest) << c["id"];
        // The sun is in the pixel meta.json names, in the direction it names.
        const auto rc = c["sun_env_pixel_rowcol"];
        const Vec3d d = equirect_direction(rc[0].get<double>(), rc[1].get<double>(), 128, 64);
        EXPECT_NEAR(dot(d, json_vec(c["sun_dir_world"])), 1.0, 1e-12);
    }
}

// Pixels that see only sky show the sky SH radiance in that direction (test photos: exposure 1).
TEST(SynthShading, SkyPixelsShowTheSkySh) {
    const std::string root = tiny_dataset();
    const auto meta = synth_test::read_json(root + "/meta.json");
    std::map<std::string, nlohmann::json> conditions;
    for (const auto& c : meta["conditions"]) conditions[c["id"]] = c;
    int checked = 0;
    for (const auto& im : meta["images"]) {
        const std::string name = im["name"];
        const auto& cond = conditions.at(im["condition"]);
        const ShCoeffs<double> sky = json_sh(cond["sky_sh"]);
        const Image photo = read_image(root + "/images/" + name),
                    mask = read_image(root + "/gt/mask/" + name);
        Camera cam;
        cam.width = im["width"], cam.height = im["height"];
        cam.fx = im["fx"], cam.fy = im["fy"], cam.cx = im["cx"], cam.cy = im["cy"];
        Mat3d c2w;
        Vec3d t;
        for (int r = 0; r < 3; ++r) {
            for (int k = 0; k < 3; ++k) c2w(r, k) = im["c2w"][r][k].get<double>();
            t[r] = im["c2w"][r][3].get<double>();
        }
        cam.rotation = transpose(c2w);
        cam.translation = -(cam.rotation * t);
        for (int y = 0; y < photo.height; ++y)
            for (int x = 0; x < photo.width; ++x) {
                if (mask.at(x, y, 0) > 0) continue;
                const Vec3d d = synth::camera_ray(cam, x + 0.5, y + 0.5).dir;
                if (dot(d, json_vec(cond["sun_dir_world"])) > 0.99) continue;  // the sun disc
                const Vec3d l = eval_sh(sky, d);
                for (int c = 0; c < 3; ++c) {
                    const int expected =
                        synth::encode_pixel(im["exposure"].get<double>(), std::max(0.0, l[c]));
                    // The four samples spread over a pixel's footprint; the SH varies slowly.
                    EXPECT_NEAR(double(photo.at(x, y, c)) * 255.0, double(expected), 2.01)
                        << name << " " << x << "," << y;
                    ++checked;
                }
            }
    }
    EXPECT_GT(checked, 100);
}

// Library-level: the sky SH is a physical (non-negative) sky, and the condition's calibration is plaza's.
TEST(SynthShading, SkyShIsNonNegativeAndCalibrated) {
    const auto conditions = synth::make_conditions(6, 2, 7);
    for (const synth::LightCondition& c : conditions) {
        for (int i = 0; i < 64; ++i)
            for (int j = 0; j < 128; ++j) {
                const Vec3d l = eval_sh(c.sky_sh, equirect_direction(i, j, 128, 64));
                EXPECT_GE(std::min({l.x, l.y, l.z}), 0.0) << c.id;
            }
        double best = 0;
        for (int i = 0; i <= 90; ++i)
            for (int j = 0; j < 180; ++j) {
                const double th = std::numbers::pi / 2 * i / 90, ph = 2 * std::numbers::pi * j / 180;
                const Vec3d n{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
                const Vec3d e = synth::sky_irradiance(c, n) + synth::sun_irradiance(c, n);
                best = std::max({best, e.x, e.y, e.z});
            }
        EXPECT_NEAR(best, synth::kMaxIrradiance, 0.02 * synth::kMaxIrradiance) << c.id;
        // environment_sh = sky + the sun's projection: the difference is the sun's power times Y(s) per band.
        const ShCoeffs<double> env = synth::environment_sh(c);
        EXPECT_NEAR(env.c[0].x - c.sky_sh.c[0].x, c.sun_power.x * sh_const::kY00, 1e-12);
        EXPECT_NEAR(env.c[2].y - c.sky_sh.c[2].y, c.sun_power.y * sh_const::kY1 * c.sun_dir.z,
                    1e-4 * c.sun_power.y);
    }
}

// The irradiance of the SH sky is its exact cosine integral (brute force over the sphere).
TEST(SynthShading, SkyIrradianceIsTheExactCosineIntegral) {
    const auto conditions = synth::make_conditions(3, 0, 3);
    for (const synth::LightCondition& c : conditions) {
        const Image pano = render_sh_panorama(c.sky_sh, 512, 256);
        for (const Vec3d n : {Vec3d{0, 0, 1}, Vec3d{1, 0, 0}, normalize(Vec3d{-0.3, 0.8, 0.2})}) {
            const Vec3d numeric = panorama_irradiance(pano, n), sh = synth::sky_irradiance(c, n);
            for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(numeric[ch], sh[ch], 2e-3 * sh[ch]) << c.id;
        }
    }
}

}  // namespace
}  // namespace lumigauss
