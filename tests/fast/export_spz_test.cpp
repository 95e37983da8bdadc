// `export --format spz` (export/spz_format.h): the file read back by a decoder written here from Niantic's
// published layout (gunzip, header, the six arrays, fixed-point positions, smallest-three rotations, SH
// bytes), and rendered in SPZ's y-up frame with the Inria SH evaluation: it reproduces the relightable
// render from cameras all around, both sides of the surfels included.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

#include "export_test_scene.h"
#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/spz_format.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/util/error.h"
#include "support/inria_sh.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using namespace lumigauss::export_test;

std::string gunzip(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string packed = ss.str();
    z_stream z{};
    const int started = inflateInit2(&z, 16 + MAX_WBITS);
    EXPECT_EQ(started, Z_OK);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(packed.data()));
    z.avail_in = uInt(packed.size());
    std::string out;
    char buffer[1 << 16];
    int result = Z_OK;
    while (result == Z_OK) {
        z.next_out = reinterpret_cast<Bytef*>(buffer);
        z.avail_out = sizeof buffer;
        result = inflate(&z, Z_NO_FLUSH);
        out.append(buffer, sizeof buffer - z.avail_out);
    }
    inflateEnd(&z);
    EXPECT_EQ(result, Z_STREAM_END) << path << " is not a whole gzip stream";
    return out;
}

struct SpzSplat {
    Vec3d position;
    double alpha = 0;
    double dc[3] = {0, 0, 0};
    Vec3d log_scale;
    Vec4<double> wxyz;
    std::vector<double> rest;  // (K - 1) x 3, channel fastest
};

struct SpzFile {
    std::uint32_t magic = 0, version = 0, count = 0;
    int degree = 0, fractional_bits = 0, flags = 0;
    std::vector<SpzSplat> splats;
};

std::uint32_t u32(const std::string& s, std::size_t at) {
    std::uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= std::uint32_t(std::uint8_t(s[at + std::size_t(b)])) << (8 * b);
    return v;
}

// The layout of github.com/nianticlabs/spz's README (version 3), decoded independently of the writer.
SpzFile read_spz(const std::string& path) {
    const std::string s = gunzip(path);
    SpzFile f;
    if (s.size() < 16) {
        ADD_FAILURE() << "no header";
        return f;
    }
    f.magic = u32(s, 0), f.version = u32(s, 4), f.count = u32(s, 8);
    f.degree = std::uint8_t(s[12]), f.fractional_bits = std::uint8_t(s[13]), f.flags = std::uint8_t(s[14]);
    const std::size_t n = f.count, rest = std::size_t((f.degree + 1) * (f.degree + 1) - 1);
    EXPECT_EQ(s.size(), 16 + n * (9 + 1 + 3 + 3 + 4 + 3 * rest)) << "array sizes";
    if (s.size() != 16 + n * (9 + 1 + 3 + 3 + 4 + 3 * rest)) return f;
    f.splats.resize(n);
    const auto byte = [&](std::size_t at) { return double(std::uint8_t(s[at])); };
    std::size_t at = 16;
    for (std::size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k, at += 3) {
            std::int32_t v = std::int32_t(std::uint8_t(s[at]) | std::uint8_t(s[at + 1]) << 8 |
                                          std::uint8_t(s[at + 2]) << 16);
            if (v & 0x800000) v -= 1 << 24;
            f.splats[i].position[k] = double(v) / double(1 << f.fractional_bits);
        }
    for (std::size_t i = 0; i < n; ++i) f.splats[i].alpha = byte(at++) / 255.0;
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) f.splats[i].dc[c] = (byte(at++) / 255.0 - 0.5) / 0.15;
    for (std::size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) f.splats[i].log_scale[k] = byte(at++) / 16.0 - 10.0;
    for (std::size_t i = 0; i < n; ++i, at += 4) {
        std::uint32_t bits = u32(s, at);
        const int largest = int(bits >> 30);
        double q[4], sum = 0;  // x y z w
        for (int k = 3; k >= 0; --k) {
            if (k == largest) continue;
            const double magnitude = double(bits & 511u) / 511.0 * std::sqrt(0.5);
            q[k] = (bits >> 9) & 1u ? -magnitude : magnitude;
            sum += q[k] * q[k];
            bits >>= 10;
        }
        q[largest] = std::sqrt(std::max(0.0, 1.0 - sum));
        f.splats[i].wxyz = {q[3], q[0], q[1], q[2]};
    }
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = 0; k < 3 * rest; ++k) f.splats[i].rest.push_back((byte(at++) - 128.0) / 128.0);
    return f;
}

// The splats as the rasterizer takes them, coloured for a camera at `eye` (SPZ frame).
SurfelBatch<float> splats_for_view(const SpzFile& f, Vec3d eye) {
    SurfelBatch<float> b;
    b.channels = 3;
    b.resize(f.splats.size());
    for (std::size_t i = 0; i < f.splats.size(); ++i) {
        const SpzSplat& s = f.splats[i];
        for (int k = 0; k < 3; ++k) b.means[3 * i + std::size_t(k)] = float(s.position[k]);
        for (int k = 0; k < 4; ++k) b.quats[4 * i + std::size_t(k)] = float(s.wxyz[k]);
        for (int k = 0; k < 2; ++k) b.scales[2 * i + std::size_t(k)] = float(std::exp(s.log_scale[k]));
        b.opacities[i] = float(s.alpha);
        const Vec3d rgb = lumigauss::testing::inria_sh_colour(
            f.degree, s.dc, [&](int k, int c) { return s.rest[std::size_t(3 * (k - 1) + c)]; },
            normalize(s.position - eye));
        for (int c = 0; c < 3; ++c) b.colors[3 * i + std::size_t(c)] = float(rgb[c]);
    }
    return b;
}

// `cam` (world frame) in SPZ's frame p' = R p: world-to-camera rotation Rc R^T, same translation.
Camera turned_camera(Camera cam, const Mat3d& R) {
    cam.rotation = cam.rotation * transpose(R);
    return cam;
}

TEST(ExportSpz, YUpRotationTakesUpToY) {
    for (const Vec3d up : {Vec3d{0, 0, 1}, Vec3d{0, -1, 0}, Vec3d{0, 1, 0}, Vec3d{0.2, -0.3, 0.9}}) {
        const Mat3d R = rotation_to_y_up(up);
        const Vec3d y = R * normalize(up);
        EXPECT_NEAR(y.x, 0, 1e-12);
        EXPECT_NEAR(y.y, 1, 1e-12);
        EXPECT_NEAR(y.z, 0, 1e-12);
        const Mat3d I = R * transpose(R);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) EXPECT_NEAR(I(i, j), i == j ? 1.0 : 0.0, 1e-12);
        EXPECT_NEAR(dot(cross(R * Vec3d{1, 0, 0}, R * Vec3d{0, 1, 0}), R * Vec3d{0, 0, 1}), 1.0, 1e-12);
    }
    // z-up worlds: +z becomes +y, +y becomes -z (a right-handed turn about x).
    const Vec3d y_of_z = rotation_to_y_up({0, 0, 1}) * Vec3d{0, 1, 0};
    EXPECT_NEAR(y_of_z.z, -1, 1e-12);
}

TEST(ExportSpz, HeaderAndKnownValues) {
    TempDir tmp("export_spz_known");
    // One surfel at (1, -2, 0.5), identity rotation, log scales (-1, -2), opacity logit 0, in a y-up world.
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(std::size_t(SurfelModel::width(ModelParam(p))), 0.0f);
    raw[int(ModelParam::Xyz)] = {1.0f, -2.0f, 0.5f};
    raw[int(ModelParam::Rotation)] = {2.0f, 0.0f, 0.0f, 0.0f};
    raw[int(ModelParam::Scaling)] = {-1.0f, -2.0f};
    const SurfelModel model = SurfelModel::from_raw(std::move(raw));
    const SurfelSides sides{{0.5f, 0.2f, 0.8f}, {0.5f, 0.2f, 0.8f}};
    write_spz_file(tmp / "one.spz", model, sides, 1, {0, 1, 0}, {});
    const SpzFile f = read_spz(tmp / "one.spz");
    ASSERT_EQ(f.splats.size(), 1u);
    EXPECT_EQ(f.magic, 0x5053474eu);
    EXPECT_EQ(f.version, 3u);
    EXPECT_EQ(f.degree, 1);
    EXPECT_EQ(f.fractional_bits, 12);
    EXPECT_EQ(f.flags, 0);
    const SpzSplat& s = f.splats[0];
    EXPECT_EQ(s.position.x, 1.0);
    EXPECT_EQ(s.position.y, -2.0);
    EXPECT_EQ(s.position.z, 0.5);
    EXPECT_NEAR(s.alpha, 128.0 / 255.0, 1e-12);  // round(127.5)
    EXPECT_EQ(s.log_scale.x, -1.0);              // (-1 + 10) * 16 = 144 exactly
    EXPECT_EQ(s.log_scale.y, -2.0);
    EXPECT_EQ(s.log_scale.z, -10.0);  // the thin axis
    EXPECT_NEAR(s.wxyz[0], 1.0, 1e-12);
    // Both sides alike: no view dependence; colour 0.5 + Y00 dc within the 8-bit step (1 / (0.15 * 255)).
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(0.5 + 0.28209479 * s.dc[c], sides.positive[std::size_t(c)], 0.004);
    for (double r : s.rest) EXPECT_EQ(r, 0.0);
    EXPECT_THROW(write_spz_file(tmp / "bad.spz", model, sides, 4, {0, 1, 0}, {}), Error);
}

// The rotation bits of a quaternion with no ties: (w, x, y, z) = (0.1, 0.7, -0.5, 0.5), x largest and
// positive; then y (sign 1, round(511 * 0.5 * sqrt 2) = 361), z (0, 361), w (0, round(72.27) = 72), the first
// in the highest bits after the 2-bit index 0: ((873 << 10 | 361) << 10) | 72.
TEST(ExportSpz, RotationBitsKnownAnswer) {
    TempDir tmp("export_spz_rotation");
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(std::size_t(SurfelModel::width(ModelParam(p))), 0.0f);
    raw[int(ModelParam::Rotation)] = {0.1f, 0.7f, -0.5f, 0.5f};
    const SurfelModel model = SurfelModel::from_raw(std::move(raw));
    const SurfelSides sides{{0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}};
    write_spz_file(tmp / "q.spz", model, sides, 0, {0, 1, 0}, {});
    const std::string s = gunzip(tmp / "q.spz");
    ASSERT_EQ(s.size(), 16u + 9 + 1 + 3 + 3 + 4);
    EXPECT_EQ(u32(s, 16 + 9 + 1 + 3 + 3), 915776584u);
    const SpzSplat back = read_spz(tmp / "q.spz").splats.at(0);
    EXPECT_NEAR(back.wxyz[0] * 0.1 + back.wxyz[1] * 0.7 - back.wxyz[2] * 0.5 + back.wxyz[3] * 0.5, 1.0, 2e-3);
}

// From cameras all around (in a z-up world, so the turn matters), the SPZ file renders like the relightable
// model; the quantisation (8-bit colours, 1/16 log-scale steps, 4-5 bit SH) costs some dB against the PLY.
void expect_spz_render(BakeShading bake, ShadingMode mode, double min_psnr) {
    TempDir tmp("export_spz_render");
    const GaussianModel model = cube_model(7);
    const ShCoeffs<float> env = moderate_env();
    const SurfelSides sides = bake_surfel_sides(model, env, bake);
    const Vec3d up{0, 0, 1};
    write_spz_file(tmp / "m.spz", model, sides, 3, up, {});
    write_spz_file(tmp / "one.spz", model, sides, 0, up, {});
    const SpzFile two_sided = read_spz(tmp / "m.spz"), one_colour = read_spz(tmp / "one.spz");
    ASSERT_EQ(two_sided.splats.size(), model.size());
    const Mat3d R = rotation_to_y_up(up);
    double worst = 1e9, worst_one = 1e9;
    for (const Camera& cam : ring_cameras()) {
        const RasterImages<float> ref = render_with_environment(model, cam, env, mode);
        const Camera turned = turned_camera(cam, R);
        const auto psnr = [&](const SpzFile& f) {
            RasterState<float> state;
            return display_psnr(
                rasterize_forward_cpu(turned, splats_for_view(f, turned.center()), {}, state).color,
                ref.color);
        };
        worst = std::min(worst, psnr(two_sided));
        worst_one = std::min(worst_one, psnr(one_colour));
    }
    std::printf("worst PSNR: SPZ degree 3 %.2f dB, one colour (+normal side) %.2f dB\n", worst, worst_one);
    EXPECT_GE(worst, min_psnr);
    EXPECT_LT(worst_one, worst - 5.0);
}

TEST(ExportSpz, RendersLikeTheModelFromBothSidesShadowed) {
    expect_spz_render(BakeShading::Shadowed, ShadingMode::Shadowed, 30.0);
}

TEST(ExportSpz, RendersLikeTheModelFromBothSidesUnshadowed) {
    expect_spz_render(BakeShading::Unshadowed, ShadingMode::Unshadowed, 30.0);
}

}  // namespace
}  // namespace lumigauss
