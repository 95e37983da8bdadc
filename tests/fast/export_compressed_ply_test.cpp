// `export --format compressed-ply` (export/compressed_ply.h): a known answer worked out by hand from
// PlayCanvas's published quantisation (three splats, bytes and words), the header the PlayCanvas engine
// checks before it takes a file for this format, and the file read back by a decoder written here the way
// the engine decodes it (lerp between the chunk bounds, smallest-three rotations, SH bytes) and rendered
// with the Inria SH evaluation: it reproduces the relightable render from cameras all around.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>

#include "export_test_scene.h"
#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/compressed_ply.h"
#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/view_sh.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/util/error.h"
#include "support/inria_sh.h"
#include "support/temp_dir.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using namespace lumigauss::export_test;

std::uint32_t u32(const std::string& s, std::size_t at) {
    std::uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= std::uint32_t(std::uint8_t(s[at + std::size_t(b)])) << (8 * b);
    return v;
}

float f32(const std::string& s, std::size_t at) {
    const std::uint32_t bits = u32(s, at);
    float v = 0;
    std::memcpy(&v, &bits, 4);
    return v;
}

struct DecodedSplat {
    Vec3d position, log_scale;
    Vec4<double> wxyz;
    double alpha = 0;
    double dc[3] = {0, 0, 0};
    std::vector<double> rest;  // channel-major, as f_rest
};

struct CompressedFile {
    std::vector<std::string> header;  // the header's lines
    std::size_t chunks = 0, vertices = 0, rest = 0;
    std::vector<DecodedSplat> splats;
};

// The engine's test for the format (elements chunk, vertex [, sh] in that order with exactly these
// properties and types) and its decoding.
CompressedFile read_compressed_ply(const std::string& s) {
    CompressedFile f;
    const std::size_t end = s.find("end_header\n");
    if (end == std::string::npos) {
        ADD_FAILURE() << "no end_header";
        return f;
    }
    std::istringstream lines(s.substr(0, end));
    for (std::string line; std::getline(lines, line);) f.header.push_back(line);
    std::vector<std::string> expected = {"ply", "format binary_little_endian 1.0"};
    std::size_t at = 2;
    while (at < f.header.size() && f.header[at].rfind("comment ", 0) == 0) ++at;
    const auto element = [&](const std::string& name) -> std::size_t {
        if (at >= f.header.size() || f.header[at].rfind("element " + name + " ", 0) != 0) return 0;
        return std::stoul(f.header[at++].substr(9 + name.size()));
    };
    const auto property = [&](const std::string& type, const std::string& name) {
        EXPECT_LT(at, f.header.size());
        if (at < f.header.size()) {
            EXPECT_EQ(f.header[at++], "property " + type + " " + name);
        }
    };
    f.chunks = element("chunk");
    for (const char* p :
         {"min_x", "min_y", "min_z", "max_x", "max_y", "max_z", "min_scale_x", "min_scale_y", "min_scale_z",
          "max_scale_x", "max_scale_y", "max_scale_z", "min_r", "min_g", "min_b", "max_r", "max_g", "max_b"})
        property("float", p);
    f.vertices = element("vertex");
    for (const char* p : {"packed_position", "packed_rotation", "packed_scale", "packed_color"})
        property("uint", p);
    if (at < f.header.size()) {
        EXPECT_EQ(element("sh"), f.vertices);
        while (at < f.header.size()) property("uchar", "f_rest_" + std::to_string(f.rest++));
        EXPECT_TRUE(f.rest == 9 || f.rest == 24 || f.rest == 45) << f.rest;
    }
    EXPECT_EQ(f.chunks, (f.vertices + 255) / 256);
    const std::size_t body = end + 11;
    EXPECT_EQ(s.size(), body + 72 * f.chunks + (16 + f.rest) * f.vertices);
    if (s.size() != body + 72 * f.chunks + (16 + f.rest) * f.vertices) return f;

    const auto unorm = [](std::uint32_t word, int shift, int bits) {
        const std::uint32_t mask = (1u << bits) - 1u;
        return double((word >> shift) & mask) / double(mask);
    };
    const auto lerp3 = [&](std::uint32_t word, std::size_t chunk_at) {
        Vec3d v;
        const double u[3] = {unorm(word, 21, 11), unorm(word, 11, 10), unorm(word, 0, 11)};
        for (int k = 0; k < 3; ++k) {
            const double lo = f32(s, chunk_at + 4 * std::size_t(k)),
                         hi = f32(s, chunk_at + 12 + 4 * std::size_t(k));
            v[k] = lo * (1 - u[k]) + hi * u[k];
        }
        return v;
    };
    const std::size_t vertex_at = body + 72 * f.chunks;
    for (std::size_t i = 0; i < f.vertices; ++i) {
        const std::size_t chunk_at = body + 72 * (i / 256), w = vertex_at + 16 * i;
        DecodedSplat d;
        d.position = lerp3(u32(s, w), chunk_at);
        d.log_scale = lerp3(u32(s, w + 8), chunk_at + 24);
        const std::uint32_t rot = u32(s, w + 4);
        const int largest = int(rot >> 30);
        double q[4], sum = 0;
        for (int k = 0, field = 0; k < 4; ++k) {
            if (k == largest) continue;
            q[k] = (unorm(rot, 20 - 10 * field++, 10) - 0.5) * std::sqrt(2.0);
            sum += q[k] * q[k];
        }
        q[largest] = std::sqrt(std::max(0.0, 1 - sum));
        d.wxyz = {q[0], q[1], q[2], q[3]};
        const std::uint32_t colour = u32(s, w + 12);
        for (int c = 0; c < 3; ++c) {
            const double lo = f32(s, chunk_at + 48 + 4 * std::size_t(c)),
                         hi = f32(s, chunk_at + 60 + 4 * std::size_t(c));
            const double u = unorm(colour, 24 - 8 * c, 8);
            d.dc[c] = (lo * (1 - u) + hi * u - 0.5) / 0.28209479177387814;
        }
        d.alpha = unorm(colour, 0, 8);
        for (std::size_t k = 0; k < f.rest; ++k)
            d.rest.push_back(
                double(std::uint8_t(s[vertex_at + 16 * f.vertices + f.rest * i + k])) * 8.0 / 255.0 - 4.0);
        f.splats.push_back(std::move(d));
    }
    return f;
}

std::string hex_words(const std::string& s, std::size_t at, std::size_t words) {
    std::string out;
    char buffer[10];
    for (std::size_t k = 0; k < words; ++k) {
        std::snprintf(buffer, sizeof buffer, "%s%08x", k ? " " : "", u32(s, at + 4 * k));
        out += buffer;
    }
    return out;
}

GaussianSplat splat(Vec3f p, Vec3f log_scale, Vec3f dc, float opacity, Vec4f rotation) {
    return {p, log_scale, rotation, opacity, dc, {}};
}

// Three splats in one chunk, worked out by hand from the quantisation rules (see the header): positions
// normalised to the bounds (0,0,0)-(1,2,4), colours 0.5 + Y00 f_dc to their bounds, rotations with the
// largest component dropped.
TEST(ExportCompressedPly, KnownAnswerForThreeSplats) {
    const std::vector<GaussianSplat> splats = {
        splat({0, 0, 0}, {-1, -2, -3}, {0, 0, 0}, 0, {1, 0, 0, 0}),
        splat({1, 2, 4}, {1, 0, -1}, {1, 1, 1}, 2, {0, 0, 0.6f, 0.8f}),
        splat({0.5f, 0.5f, 1}, {0, -1, -2}, {0.5f, -0.5f, 0.25f}, -1, {0.9f, -0.3f, 0.2f, 0.1f}),
    };
    const std::string s = compressed_ply_bytes(splats, 0);
    const std::size_t body = s.find("end_header\n") + 11;
    ASSERT_EQ(s.size(), body + 72 + 3 * 16);
    // Bounds: position, log scale, colour (0.5 - 0.5 Y00 = 0.35895261 as float: 0x3eb7c8a3).
    EXPECT_EQ(hex_words(s, body, 18),
              "00000000 00000000 00000000 3f800000 40000000 40800000 bf800000 c0000000 c0400000 3f800000 "
              "00000000 bf800000 3f000000 3eb7c8a3 3f000000 3f48375d 3f48375d 3f48375d");
    // Position, rotation, scale, colour words. Splat 1: rotation index 3 (0.8), (0, 0, 0.6) as 512 512 946;
    // alpha round(255 sigmoid 2) = 225. Splat 2: position (1024, 256, 512), rotation index 0 of the
    // normalised quaternion, colour (128, 0, 64), alpha 69.
    EXPECT_EQ(hex_words(s, body + 72, 4), "00000000 20080200 00000000 00550080");
    EXPECT_EQ(hex_words(s, body + 88, 4), "ffffffff e00803b2 ffffffff ffffffe1");
    EXPECT_EQ(hex_words(s, body + 104, 4), "80080200 121a524a 80100400 80004045");
}

TEST(ExportCompressedPly, ShBytesAndTheLastPartialChunk) {
    std::vector<GaussianSplat> splats;
    for (int i = 0; i < 300; ++i) {
        GaussianSplat g = splat({float(i), 0, 0}, {-3, -3, -13.8f}, {0, 0, 0}, 1, {1, 0, 0, 0});
        g.rest.assign(9, 0.0f);
        g.rest[0] = 0.1f, g.rest[1] = -0.5f, g.rest[2] = -4.0f, g.rest[3] = 4.0f;
        splats.push_back(std::move(g));
    }
    const std::string s = compressed_ply_bytes(splats, 1);
    const CompressedFile f = read_compressed_ply(s);
    EXPECT_EQ(f.chunks, 2u);
    ASSERT_EQ(f.splats.size(), 300u);
    // The second chunk's bounds are those of its 44 splats: x from 256 to 299.
    const std::size_t body = s.find("end_header\n") + 11;
    EXPECT_EQ(f32(s, body + 72), 256.0f);
    EXPECT_EQ(f32(s, body + 72 + 12), 299.0f);
    EXPECT_NEAR(f.splats[299].position.x, 299.0, 1e-4);
    EXPECT_NEAR(f.splats[270].position.x, 270.0, 44.0 / 2047);
    const std::size_t sh_at = body + 2 * 72 + 300 * 16;
    EXPECT_EQ(std::uint8_t(s[sh_at + 0]), 131);  // 0.1
    EXPECT_EQ(std::uint8_t(s[sh_at + 1]), 112);  // -0.5
    EXPECT_EQ(std::uint8_t(s[sh_at + 2]), 0);    // -4
    EXPECT_EQ(std::uint8_t(s[sh_at + 3]), 255);  // 4, clamped
    EXPECT_EQ(std::uint8_t(s[sh_at + 4]), 128);  // 0
}

TEST(ExportCompressedPly, MortonOrderGroupsNeighbours) {
    // Two clusters, interleaved in the input: the order visits one cluster, then the other.
    std::vector<Vec3f> points;
    for (int i = 0; i < 8; ++i) {
        const float step = 0.1f * float(i);
        points.push_back(i % 2 ? Vec3f{10.0f + step, 10, 10} : Vec3f{step, 0, 0});
    }
    const std::vector<std::size_t> order = morton_order(points);
    ASSERT_EQ(order.size(), 8u);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(order[std::size_t(k)] % 2, 0u) << k;
    for (int k = 4; k < 8; ++k) EXPECT_EQ(order[std::size_t(k)] % 2, 1u) << k;
    // All in one place: the input order.
    const std::vector<Vec3f> same(5, Vec3f{1, 2, 3});
    EXPECT_EQ(morton_order(same), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
}

TEST(ExportCompressedPly, RefusesWhatItCannotWrite) {
    std::vector<GaussianSplat> splats = {splat({0, 0, 0}, {0, 0, 0}, {0, 0, 0}, 0, {1, 0, 0, 0})};
    EXPECT_THROW(compressed_ply_bytes(splats, 4), Error);
    EXPECT_THROW(compressed_ply_bytes(splats, 1), Error) << "degree 1 needs 9 SH values";
    splats[0].position.y = std::nanf("");
    EXPECT_THROW(compressed_ply_bytes(splats, 0), Error);
}

// The splats as the rasterizer takes them, coloured for a camera at `eye`.
SurfelBatch<float> splats_for_view(const CompressedFile& f, Vec3d eye, int degree) {
    SurfelBatch<float> b;
    b.channels = 3;
    b.resize(f.splats.size());
    const std::size_t per_channel = f.rest / 3;
    for (std::size_t i = 0; i < f.splats.size(); ++i) {
        const DecodedSplat& s = f.splats[i];
        for (int k = 0; k < 3; ++k) b.means[3 * i + std::size_t(k)] = float(s.position[k]);
        for (int k = 0; k < 4; ++k) b.quats[4 * i + std::size_t(k)] = float(s.wxyz[k]);
        for (int k = 0; k < 2; ++k) b.scales[2 * i + std::size_t(k)] = float(std::exp(s.log_scale[k]));
        b.opacities[i] = float(s.alpha);
        const Vec3d rgb = lumigauss::testing::inria_sh_colour(
            degree, s.dc,
            [&](int k, int c) { return s.rest[std::size_t(c) * per_channel + std::size_t(k - 1)]; },
            normalize(s.position - eye));
        for (int c = 0; c < 3; ++c) b.colors[3 * i + std::size_t(c)] = float(rgb[c]);
    }
    return b;
}

// From cameras all around, the file renders like the relightable model; both sides of each surfel show
// their own colour at degree 3, and a one-colour file (degree 0) does not.
TEST(ExportCompressedPly, RendersLikeTheModelFromBothSides) {
    TempDir tmp("export_compressed_ply");
    const GaussianModel model = cube_model(7, 300);
    const ShCoeffs<float> env = moderate_env();
    const SurfelSides sides = bake_surfel_sides(model, env, BakeShading::Shadowed);
    write_compressed_ply(tmp / "m.ply", model, two_sided_view_sh(model, sides, 3, {}), 3);
    write_compressed_ply(tmp / "one.ply", model, two_sided_view_sh(model, sides, 0, {}), 0);
    const CompressedFile three = read_compressed_ply(synth_test::read_bytes(tmp / "m.ply"));
    const CompressedFile one = read_compressed_ply(synth_test::read_bytes(tmp / "one.ply"));
    ASSERT_EQ(three.splats.size(), model.size());
    EXPECT_EQ(three.rest, 45u);
    EXPECT_EQ(one.rest, 0u);
    double worst = 1e9, worst_one = 1e9;
    for (const Camera& cam : ring_cameras()) {
        const RasterImages<float> ref = render_with_environment(model, cam, env, ShadingMode::Shadowed);
        const auto psnr = [&](const CompressedFile& f, int degree) {
            RasterState<float> state;
            return display_psnr(
                rasterize_forward_cpu(cam, splats_for_view(f, cam.center(), degree), {}, state).color,
                ref.color);
        };
        worst = std::min(worst, psnr(three, 3));
        worst_one = std::min(worst_one, psnr(one, 0));
    }
    std::printf("worst PSNR: compressed PLY degree 3 %.2f dB, one colour %.2f dB\n", worst, worst_one);
    EXPECT_GE(worst, 30.0);
    EXPECT_LT(worst_one, worst - 5.0);
}

}  // namespace
}  // namespace lumigauss
