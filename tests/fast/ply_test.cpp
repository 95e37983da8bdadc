// PLY container and the 2DGS surfel layout (and what the relightable reader refuses): round trips, foreign
// encodings, errors, activations, view SH.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "io_test_util.h"
#include "lumigauss/io/ply.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/model/splat_ply.h"
#include "lumigauss/model/view_sh.h"

namespace lumigauss {
namespace {

using test::expect_error;
using test::TempDir;
using test::write_text;

TEST(Ply, BinaryRoundTripIsExact) {
    TempDir dir;
    PlyVertexTable t;
    t.add("x", {1.5f, -2.25f, 3e-7f});
    t.add("opacity", {0.f, -1.f, 1e20f});
    write_ply_vertices(dir / "a.ply", t);
    const PlyVertexTable r = read_ply_vertices(dir / "a.ply");
    EXPECT_EQ(r.count, 3u);
    EXPECT_EQ(r.names, t.names);
    EXPECT_EQ(r.columns, t.columns);
    EXPECT_FALSE(std::filesystem::exists(dir / "a.ply.tmp"));
}

TEST(Ply, ReadsAsciiWithFacesAndMixedTypes) {
    TempDir dir;
    write_text(dir / "a.ply",
               "ply\nformat ascii 1.0\ncomment hi\nelement vertex 2\nproperty float x\nproperty uchar red\n"
               "property double y\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
               "1.5 255 -2\n0.25 3 4.5\n3 0 1 1\n");
    const PlyVertexTable r = read_ply_vertices(dir / "a.ply");
    ASSERT_EQ(r.count, 2u);
    EXPECT_EQ(r.column("x", "")[0], 1.5f);
    EXPECT_EQ(r.column("red", "")[0], 255.f);
    EXPECT_EQ(r.column("y", "")[1], 4.5f);
}

TEST(Ply, ReadsBigEndianAndSkipsBinaryListElements) {
    TempDir dir;
    std::ofstream out(dir / "b.ply", std::ios::binary);
    out << "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\nproperty short s\n"
           "element face 1\nproperty list uchar int idx\nelement vertex2 0\nend_header\n";
    const auto put_be = [&](const void* p, int n) {
        const auto* b = static_cast<const unsigned char*>(p);
        for (int i = n - 1; i >= 0; --i) out.put(char(b[i]));
    };
    const float x = -3.5f;
    const short s = -7;
    put_be(&x, 4), put_be(&s, 2);
    out.put(char(2));
    const int idx[2] = {4, 5};
    put_be(&idx[0], 4), put_be(&idx[1], 4);
    out.close();
    const PlyVertexTable r = read_ply_vertices(dir / "b.ply");
    EXPECT_EQ(r.column("x", "")[0], -3.5f);
    EXPECT_EQ(r.column("s", "")[0], -7.f);
}

// The reader takes the records in blocks of 64 KB: records that straddle a block's end, every scalar type,
// both byte orders, a second element after the vertices, and a file cut inside a later block.
TEST(Ply, ManyMixedRecordsAcrossBlocksInBothByteOrders) {
    constexpr int kCount = 20000;  // 15 bytes a record: 4369 per block, the last one partial
    const auto value = [](int i, int k) { return double((i * 7 + k * 13) % 251) - 120.0; };
    for (const bool big : {false, true}) {
        TempDir dir;
        const std::string path = dir / "m.ply";
        std::ofstream out(path, std::ios::binary);
        out << "ply\nformat " << (big ? "binary_big_endian" : "binary_little_endian")
            << " 1.0\nelement vertex " << kCount
            << "\nproperty char a\nproperty uchar b\nproperty ushort c\nproperty int d\nproperty double e\n"
               "element extra 1\nproperty float f\nend_header\n";
        const auto put = [&](auto v) {
            unsigned char b[sizeof v];
            std::memcpy(b, &v, sizeof v);
            if (big) std::reverse(b, b + sizeof v);
            out.write(reinterpret_cast<const char*>(b), sizeof v);
        };
        for (int i = 0; i < kCount; ++i) {
            put(std::int8_t(value(i, 0)));
            put(std::uint8_t(value(i, 1) + 120));
            put(std::uint16_t(value(i, 2) + 120));
            put(std::int32_t(value(i, 3)));
            put(double(value(i, 4)) / 4);
        }
        put(1.25f);
        out.close();
        const PlyVertexTable r = read_ply_vertices(path);
        ASSERT_EQ(r.count, std::size_t(kCount));
        for (int i : {0, 4368, 4369, 4370, 8738, 19999}) {
            EXPECT_EQ(r.column("a", "")[i], float(value(i, 0))) << i;
            EXPECT_EQ(r.column("b", "")[i], float(value(i, 1) + 120)) << i;
            EXPECT_EQ(r.column("c", "")[i], float(value(i, 2) + 120)) << i;
            EXPECT_EQ(r.column("d", "")[i], float(value(i, 3))) << i;
            EXPECT_EQ(r.column("e", "")[i], float(value(i, 4) / 4)) << i;
        }
        // The vertex count is checked against the file's size before anything is read; a cut in an element
        // after the vertices is found by the block read itself (two bytes of the last float missing).
        std::filesystem::resize_file(path, std::filesystem::file_size(path) - 2);
        expect_error([&] { read_ply_vertices(path); }, {path, "'extra'", "record 0"});
    }
}

// An element without properties holds no bytes however many records it declares; counting through them
// hung the reader (libFuzzer, fuzz/regressions/ply_vertices/element_without_properties).
TEST(Ply, ElementsWithoutPropertiesAreSkippedAtOnce) {
    TempDir dir;
    std::ofstream out(dir / "e.ply", std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement empty 1000000000000000\nelement vertex 1\n"
           "property float x\nend_header\n";
    const float x = 2.5f;
    out.write(reinterpret_cast<const char*>(&x), 4);
    out.close();
    EXPECT_EQ(read_ply_vertices(dir / "e.ply").column("x", "")[0], 2.5f);
}

// A vertex element without properties holds no bytes, so no file size bounds its count, and the model
// readers sized their arrays by it (libFuzzer: a 184-byte relightable PLY declaring 671,698,203,059 vertices
// asked for 8 TB; fuzz/regressions/relightable_ply/vertex_without_properties). Refused, and so is a second
// vertex element.
TEST(Ply, AVertexElementWithoutPropertiesOrTwiceIsRefused) {
    TempDir dir;
    write_text(dir / "bare.ply",
               "ply\nformat binary_little_endian 1.0\nelement vertex 671698203059\nend_header\n");
    expect_error([&] { read_ply_vertices(dir / "bare.ply"); },
                 {"bare.ply", "671698203059 vertices but no properties"});
    expect_error([&] { load_2dgs_ply(dir / "bare.ply"); }, {"bare.ply", "no properties"});
    expect_error([&] { load_relightable_ply(dir / "bare.ply"); }, {"bare.ply", "no properties"});
    write_text(dir / "twice.ply",
               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement vertex 1\nproperty float "
               "y\nend_header\n1\n2\n");
    expect_error([&] { read_ply_vertices(dir / "twice.ply"); },
                 {"twice.ply", "'vertex' element is declared twice"});
    // A model reader looks up its columns before it allocates for them.
    write_text(dir / "x_only.ply",
               "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n2\n");
    expect_error([&] { load_2dgs_ply(dir / "x_only.ply"); }, {"x_only.ply", "'y'"});
    expect_error([&] { load_relightable_ply(dir / "x_only.ply"); }, {"x_only.ply", "'y'"});
}

TEST(Ply, ErrorsNameTheFileAndTheProblem) {
    TempDir dir;
    expect_error([&] { read_ply_vertices(dir / "missing.ply"); }, {"missing.ply", "cannot open"});
    write_text(dir / "notply.ply", "hello\n");
    expect_error([&] { read_ply_vertices(dir / "notply.ply"); }, {"notply.ply", "not a PLY"});
    write_text(dir / "trunc.ply",
               "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty float x\nend_header\nabcd");
    expect_error([&] { read_ply_vertices(dir / "trunc.ply"); }, {"trunc.ply", "truncated"});
    // A property declared twice (which column is meant?) and binary data past the declared records (a count
    // that undercounts the file) were read silently.
    write_text(dir / "twice.ply",
               "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float x\n"
               "end_header\nabcdabcd");
    expect_error([&] { read_ply_vertices(dir / "twice.ply"); }, {"twice.ply", "'x'", "declared twice"});
    write_text(dir / "more.ply",
               "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nend_header\n"
               "\x01\x02\x03\x04\x05\x06\x07\x08");
    expect_error([&] { read_ply_vertices(dir / "more.ply"); },
                 {"more.ply", "after the last declared record"});
    // A tiny file declaring a huge count fails before anything is allocated for it (it used to ask for 4 TB
    // per column and end in std::bad_alloc, or the OOM killer for smaller counts).
    write_text(dir / "huge.ply",
               "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\n"
               "end_header\nabcd");
    expect_error([&] { read_ply_vertices(dir / "huge.ply"); },
                 {"huge.ply", "declares 1000000000000", "4 bytes"});
    write_text(dir / "huge_ascii.ply",
               "ply\nformat ascii 1.0\nelement vertex 20000000\nproperty float x\nproperty float "
               "y\nend_header\n1 2\n");
    expect_error([&] { read_ply_vertices(dir / "huge_ascii.ply"); }, {"huge_ascii.ply", "declares 20000000"});
    write_text(dir / "nan.ply",
               "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\nnan\n");
    expect_error([&] { read_ply_vertices(dir / "nan.ply"); }, {"nan.ply"});
    write_text(dir / "type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n");
    expect_error([&] { read_ply_vertices(dir / "type.ply"); }, {"type.ply", "quad"});
    PlyVertexTable t;
    t.add("x", {1.f});
    write_ply_vertices(dir / "ok.ply", t);
    expect_error([&] { load_2dgs_ply(dir / "ok.ply"); }, {"ok.ply", "'y'"});
}

ViewDependentSurfels random_model(int degree, std::size_t n) {
    ViewDependentSurfels m;
    m.sh_degree = degree;
    m.surfels.resize(n);
    m.sh.resize(n * std::size_t(view_sh_coefficients(degree)) * 3);
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) m.surfels.means[3 * i + k] = float(i) * 0.1f + float(k);
        for (int k = 0; k < 4; ++k) m.surfels.quats[4 * i + k] = 0.3f + 0.1f * float(k + i);
        m.surfels.scales[2 * i] = 0.01f * float(i + 1), m.surfels.scales[2 * i + 1] = 0.02f;
        m.surfels.opacities[i] = 0.1f + 0.08f * float(i);
    }
    for (std::size_t j = 0; j < m.sh.size(); ++j) m.sh[j] = std::sin(float(j));
    return m;
}

TEST(SplatPly, RoundTripKeepsEveryFieldForEachDegree) {
    TempDir dir;
    for (int degree = 0; degree <= 3; ++degree) {
        const ViewDependentSurfels m = random_model(degree, 7);
        save_2dgs_ply(dir / "m.ply", m);
        const ViewDependentSurfels r = load_2dgs_ply(dir / "m.ply");
        EXPECT_EQ(r.sh_degree, degree);
        ASSERT_EQ(r.size(), m.size());
        for (std::size_t j = 0; j < m.sh.size(); ++j) EXPECT_FLOAT_EQ(r.sh[j], m.sh[j]);
        for (std::size_t j = 0; j < m.surfels.means.size(); ++j)
            EXPECT_FLOAT_EQ(r.surfels.means[j], m.surfels.means[j]);
        for (std::size_t j = 0; j < m.surfels.quats.size(); ++j)
            EXPECT_FLOAT_EQ(r.surfels.quats[j], m.surfels.quats[j]);
        for (std::size_t j = 0; j < m.surfels.scales.size(); ++j)
            EXPECT_NEAR(r.surfels.scales[j], m.surfels.scales[j], 1e-6f * m.surfels.scales[j]);
        for (std::size_t j = 0; j < m.size(); ++j)
            EXPECT_NEAR(r.surfels.opacities[j], m.surfels.opacities[j], 1e-6f);
    }
}

TEST(SplatPly, ActivationsFollowThe2dgsLayout) {
    TempDir dir;
    PlyVertexTable t;
    for (const char* n : {"x", "y", "z", "f_dc_1", "f_dc_2", "rot_1", "rot_2", "rot_3"}) t.add(n, {0.f});
    t.add("f_dc_0", {1.f});
    t.add("opacity", {0.f});  // logit 0 -> 0.5
    t.add("scale_0", {std::log(0.25f)});
    t.add("scale_1", {0.f});
    t.add("rot_0", {2.f});
    write_ply_vertices(dir / "one.ply", t);
    ViewDependentSurfels m = load_2dgs_ply(dir / "one.ply");
    EXPECT_EQ(m.sh_degree, 0);
    EXPECT_FLOAT_EQ(m.surfels.opacities[0], 0.5f);
    EXPECT_FLOAT_EQ(m.surfels.scales[0], 0.25f);
    EXPECT_FLOAT_EQ(m.surfels.scales[1], 1.f);
    colors_for_view(m, {0, 0, -5});
    EXPECT_NEAR(m.surfels.colors[0], 0.5f + 0.282095f, 1e-6f);  // colour = 0.5 + C0 * f_dc, clamped at 0
    EXPECT_NEAR(m.surfels.colors[1], 0.5f, 1e-6f);
}

TEST(SplatPly, WrongRestCountAndZeroQuaternionAreErrors) {
    TempDir dir;
    PlyVertexTable t;
    for (const char* n : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
                          "rot_0", "rot_1", "rot_2", "rot_3", "f_rest_0", "f_rest_1"})
        t.add(n, {0.f});
    write_ply_vertices(dir / "rest.ply", t);
    expect_error([&] { load_2dgs_ply(dir / "rest.ply"); }, {"rest.ply", "f_rest"});
    PlyVertexTable z;
    for (const char* n : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
                          "rot_0", "rot_1", "rot_2", "rot_3"})
        z.add(n, {0.f});
    write_ply_vertices(dir / "zq.ply", z);
    expect_error([&] { load_2dgs_ply(dir / "zq.ply"); }, {"zq.ply", "zero quaternion"});
}

TEST(ViewSh, DegreeOneFollowsTheInriaSignConvention) {
    // Coefficient 3 multiplies -C1 * x: a positive value darkens surfels seen looking along +x.
    float sh[4 * 3] = {};
    sh[3 * 3] = 1.f;
    EXPECT_NEAR(eval_view_sh(1, sh, Vec3f{1, 0, 0}).x, -0.4886025f, 1e-6f);
    EXPECT_NEAR(eval_view_sh(1, sh, Vec3f{-1, 0, 0}).x, 0.4886025f, 1e-6f);
    float sh2[4 * 3] = {};
    sh2[2 * 3 + 1] = 1.f;  // coefficient 2: +C1 * z, green channel
    EXPECT_NEAR(eval_view_sh(1, sh2, Vec3f{0, 0, 1}).y, 0.4886025f, 1e-6f);
}

TEST(ViewSh, HigherDegreesAreOrthonormalUpToTheirConstants) {
    // Each basis function of degrees 2 and 3 integrates to 1 in square over the sphere.
    const int n = 256;
    for (int k = 4; k < 16; ++k) {
        double integral = 0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < 2 * n; ++j) {
                const double th = M_PI * (i + 0.5) / n, ph = M_PI * (j + 0.5) / n;
                float sh[16 * 3] = {};
                sh[3 * k] = 1.f;
                const Vec3f d{float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                              float(std::cos(th))};
                const double v = eval_view_sh(3, sh, d).x;
                integral += v * v * std::sin(th) * (M_PI / n) * (M_PI / n);
            }
        EXPECT_NEAR(integral, 1.0, 2e-3) << "coefficient " << k;
    }
}

}  // namespace
}  // namespace lumigauss
