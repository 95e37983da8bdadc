// Image files (PNG 8/16, EXR, HDR, JPEG via stb), area resizing and the sRGB curves.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "fast/io_test_util.h"
#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/image.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using test::expect_error;
using test::TempDir;

void expect_same_pixels(const Image& a, const Image& b) {
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    ASSERT_EQ(a.channels, b.channels);
    for (std::size_t i = 0; i < a.pixels.size(); ++i) ASSERT_EQ(a.pixels[i], b.pixels[i]) << "sample " << i;
}

TEST(IoImage, Png8RoundTripKeepsChannelCounts) {
    TempDir tmp;
    for (int c = 1; c <= 4; ++c) {
        const Image im = test::test_image(13, 7, c);
        const std::string path = tmp / (std::to_string(c) + "_channels.png");
        write_png(path, im);
        expect_same_pixels(read_image(path), im);
        const ImageInfo info = read_image_info(path);
        EXPECT_EQ(info.width, 13);
        EXPECT_EQ(info.height, 7);
        EXPECT_EQ(info.channels, c);
    }
}

TEST(IoImage, Png16RoundTripIsExact) {
    TempDir tmp;
    for (int c : {1, 3, 4}) {
        Image im(9, 5, c);
        for (std::size_t i = 0; i < im.pixels.size(); ++i)
            im.pixels[i] = float((i * 4099) % 65536) / 65535.0f;
        const std::string path = tmp / "b.png";
        write_png(path, im, 16);
        expect_same_pixels(read_image(path), im);
    }
}

TEST(IoImage, PngClampsAndRounds) {
    TempDir tmp;
    Image im(4, 1, 1);
    im.pixels = {-1.0f, 2.0f, std::numeric_limits<float>::quiet_NaN(), 0.5f};
    write_png(tmp / "c.png", im);
    const Image back = read_image(tmp / "c.png");
    EXPECT_EQ(back.pixels[0], 0.0f);
    EXPECT_EQ(back.pixels[1], 1.0f);
    EXPECT_EQ(back.pixels[2], 0.0f);
    EXPECT_EQ(back.pixels[3], 128.0f / 255.0f);  // 127.5 rounds up
}

TEST(IoImage, ExrRoundTripIsExactFloat) {
    TempDir tmp;
    Image rgb(6, 4, 3);
    for (std::size_t i = 0; i < rgb.pixels.size(); ++i) rgb.pixels[i] = std::pow(1.7f, float(i % 40) - 20.0f);
    write_exr(tmp / "e.exr", rgb);
    expect_same_pixels(read_image(tmp / "e.exr"), rgb);
    EXPECT_EQ(read_image_info(tmp / "e.exr").channels, 3);

    Image gray(5, 3, 1);
    for (std::size_t i = 0; i < gray.pixels.size(); ++i) gray.pixels[i] = float(i) * 0.25f;
    write_exr(tmp / "g.exr", gray);
    expect_same_pixels(read_image(tmp / "g.exr"), gray);
}

TEST(IoImage, ReadsJpegAndRadianceHdr) {
    TempDir tmp;
    const Image im = test::test_image(16, 8, 3);
    std::vector<unsigned char> bytes(im.pixels.size());
    for (std::size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = static_cast<unsigned char>(std::lround(im.pixels[i] * 255));
    ASSERT_TRUE(stbi_write_jpg((tmp / "a.jpg").c_str(), 16, 8, 3, bytes.data(), 100));
    const Image jpg = read_image(tmp / "a.jpg");
    ASSERT_EQ(jpg.channels, 3);
    double error = 0;
    for (std::size_t i = 0; i < im.pixels.size(); ++i) error += std::abs(jpg.pixels[i] - im.pixels[i]);
    EXPECT_LT(error / double(im.pixels.size()), 0.03);  // lossy, but close at quality 100

    Image radiance(4, 2, 3);
    for (std::size_t i = 0; i < radiance.pixels.size(); ++i) radiance.pixels[i] = 0.01f * float(i * i) + 0.5f;
    ASSERT_TRUE(stbi_write_hdr((tmp / "a.hdr").c_str(), 4, 2, 3, radiance.pixels.data()));
    const Image hdr = read_image(tmp / "a.hdr");  // float radiance, not divided by anything
    ASSERT_EQ(hdr.channels, 3);
    for (std::size_t i = 0; i < hdr.pixels.size(); ++i)
        EXPECT_NEAR(hdr.pixels[i], radiance.pixels[i], 0.02f * radiance.pixels[i]);
}

TEST(IoImage, WritesAreAtomic) {
    TempDir tmp;
    const std::string path = tmp / "keep.png";
    write_png(path, test::test_image(4, 4, 3));
    EXPECT_FALSE(std::filesystem::exists(temp_path_for(path)));
    // A writer that fails half-way leaves the old file untouched and no temporary behind.
    EXPECT_THROW(write_atomically(path,
                                  [](const std::string& t) {
                                      test::write_text(t, "partial");
                                      throw Error("disk full");
                                  }),
                 Error);
    EXPECT_FALSE(std::filesystem::exists(temp_path_for(path)));
    expect_same_pixels(read_image(path), test::test_image(4, 4, 3));
}

TEST(IoImage, ReadsPlazaFiles) {
    const std::string plaza = test::plaza_dir();
    if (plaza.empty()) GTEST_SKIP() << "shared data/plaza_mini not present";
    const Image photo = read_image(plaza + "/images/train_0000.png");
    EXPECT_EQ(photo.width, 128);
    EXPECT_EQ(photo.height, 96);
    EXPECT_EQ(photo.channels, 3);
    EXPECT_EQ(read_image(plaza + "/masks/train_0000.png").channels, 1);
    const Image albedo = read_image(plaza + "/gt/albedo/train_0000.png");  // 16 bit: codes / 65535
    EXPECT_EQ(albedo.channels, 3);
    for (float v : albedo.pixels) ASSERT_EQ(std::round(v * 65535.0f), v * 65535.0f);
    const Image exr = read_image(plaza + "/env/sky00.exr"), hdr = read_image(plaza + "/env/sky00.hdr");
    ASSERT_EQ(exr.width, 128);
    ASSERT_EQ(exr.height, 64);
    ASSERT_EQ(hdr.channels, 3);
    ASSERT_EQ(exr.pixels.size(), hdr.pixels.size());
    // RGBE keeps 8 mantissa bits relative to the pixel's largest channel.
    for (std::size_t p = 0; p < exr.pixels.size(); p += 3) {
        const float largest = std::max({exr.pixels[p], exr.pixels[p + 1], exr.pixels[p + 2]});
        for (std::size_t c = 0; c < 3; ++c)
            ASSERT_NEAR(hdr.pixels[p + c], exr.pixels[p + c], largest / 64 + 1e-6f);
    }
}

TEST(IoImage, ErrorsNameTheFile) {
    TempDir tmp;
    expect_error([&] { read_image(tmp / "missing.png"); }, {"missing.png", "not found"});
    test::write_text(tmp / "garbage.png", "this is not a png at all");
    expect_error([&] { read_image(tmp / "garbage.png"); }, {"garbage.png"});
    expect_error([&] { read_image_info(tmp / "garbage.png"); }, {"garbage.png"});
    write_png(tmp / "full.png", test::test_image(32, 32, 3));
    const std::string bytes = test::read_text(tmp / "full.png");
    test::write_text(tmp / "cut.png", bytes.substr(0, bytes.size() / 2));
    expect_error([&] { read_image(tmp / "cut.png"); }, {"cut.png"});
    test::write_text(tmp / "cut.exr", "v/1\x01 truncated");
    expect_error([&] { read_image(tmp / "cut.exr"); }, {"cut.exr"});
    expect_error([&] { write_png(tmp / "no_such_dir/x.png", test::test_image(2, 2, 3)); }, {"x.png"});
    expect_error([&] { write_png(tmp / "x.png", test::test_image(2, 2, 3), 12); }, {"x.png", "8 or 16"});
}

// stb_image decodes a cut Radiance file as if its missing scanlines were black, and `env` then projected
// a black sky without a word. Both scanline layouts: run-length encoded (width >= 8) and flat.
TEST(IoImage, CutRadianceHdrIsRefused) {
    TempDir tmp;
    for (const int width : {64, 4}) {
        Image radiance(width, 32, 3);
        for (std::size_t i = 0; i < radiance.pixels.size(); ++i) radiance.pixels[i] = 0.5f + float(i % 7);
        const std::string full = tmp / "full.hdr";
        ASSERT_TRUE(stbi_write_hdr(full.c_str(), width, 32, 3, radiance.pixels.data()));
        EXPECT_EQ(read_image(full).width, width);
        const std::string bytes = test::read_text(full);
        const std::size_t header = bytes.find("+X");
        ASSERT_NE(header, std::string::npos);
        for (const std::size_t keep : {header + 8, bytes.size() / 2, bytes.size() - 1}) {
            test::write_text(tmp / "cut.hdr", bytes.substr(0, keep));
            expect_error([&] { read_image(tmp / "cut.hdr"); }, {"cut.hdr", "truncated"});
        }
    }
    test::write_text(tmp / "headless.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n");
    expect_error([&] { read_image(tmp / "headless.hdr"); }, {"headless.hdr"});
}

// stb_image read the pixels a cut TGA lacks as zeros (fuzz_image: a 4 KB file declaring 12336 x 2608 gave
// 515 MB of floats). Uncompressed and run-length encoded TGAs must hold the pixels they declare.
TEST(IoImage, CutTgaIsRefused) {
    TempDir tmp;
    std::vector<unsigned char> rgb(16 * 8 * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<unsigned char>(i * 5);
    for (const int rle : {0, 1}) {
        stbi_write_tga_with_rle = rle;
        const std::string full = tmp / "full.tga";
        ASSERT_TRUE(stbi_write_tga(full.c_str(), 16, 8, 3, rgb.data()));
        const Image back = read_image(full);
        EXPECT_EQ(back.width, 16);
        EXPECT_EQ(back.height, 8);
        const std::string bytes = test::read_text(full);
        if (!rle) {  // cut in the pixels
            test::write_text(tmp / "cut.tga", bytes.substr(0, 18 + 16 * 8 * 3 / 2));
            expect_error([&] { read_image(tmp / "cut.tga"); }, {"cut.tga", "truncated"});
        }
        // The header alone, declaring 12336 x 2608 (the fuzzer's input had 4 KB of it).
        std::string header = bytes.substr(0, 18);
        header[12] = char(0x30), header[13] = char(0x30), header[14] = char(0x30), header[15] = char(0x0a);
        test::write_text(tmp / "huge.tga", header + std::string(4096, '\x01'));
        expect_error([&] { read_image(tmp / "huge.tga"); }, {"huge.tga", "truncated"});
    }
    stbi_write_tga_with_rle = 1;
}

// A 379 KB PNG declaring 20000 x 20000 pixels took 1.9 GB before failing without naming the file. The
// declared size is now checked against kMaxImagePixels before anything is decoded.
TEST(IoImage, DeclaredSizeOverTheLimitIsRefused) {
    TempDir tmp;
    const auto big_endian = [](std::uint32_t v) {
        return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
    };
    const auto crc32 = [](const std::string& data) {
        std::uint32_t c = 0xffffffffu;
        for (const unsigned char byte : data) {
            c ^= byte;
            for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
        }
        return ~c;
    };
    const auto png_declaring = [&](std::uint32_t width, std::uint32_t height) {
        const std::string ihdr = "IHDR" + big_endian(width) + big_endian(height) + std::string{8, 2, 0, 0, 0};
        return std::string("\x89PNG\r\n\x1a\n", 8) + big_endian(13) + ihdr + big_endian(crc32(ihdr));
    };
    // Under stb's own 1 GiB bound: the header reads, the pixels are refused.
    test::write_text(tmp / "large.png", png_declaring(15000, 15000));
    EXPECT_EQ(read_image_info(tmp / "large.png").width, 15000);
    expect_error([&] { read_image(tmp / "large.png"); }, {"large.png", "15000 x 15000", "limit"});
    // Within the limit but far more than 33 bytes can encode: refused before stb allocates 7.5 MB for it.
    test::write_text(tmp / "tiny.png", png_declaring(2500, 1000));
    expect_error([&] { read_image(tmp / "tiny.png"); }, {"tiny.png", "2500 x 1000", "bytes can hold"});
    // Over it (stb says "unknown image type"): the declared size is still what the message names.
    test::write_text(tmp / "huge.png", png_declaring(20000, 20000));
    expect_error([&] { read_image_info(tmp / "huge.png"); }, {"huge.png", "20000 x 20000", "limit"});
    expect_error([&] { read_image(tmp / "huge.png"); }, {"huge.png", "20000 x 20000", "limit"});
    // A chunk declaring more bytes than the file holds (stb grew its buffer to it first: a 210-byte file
    // asked for 2 GB; found by fuzz_image). A valid image's chunks all fit.
    const std::string idat = "IDAT" + std::string(16, '\0');
    test::write_text(tmp / "cut.png", png_declaring(9, 3) + big_endian(0x40000000u) + idat);
    expect_error([&] { read_image(tmp / "cut.png"); }, {"cut.png", "chunk 'IDAT'", "1073741824 bytes"});
    Image small(9, 3, 3);
    write_png(tmp / "whole.png", small, 8);
    EXPECT_EQ(read_image(tmp / "whole.png").width, 9);
}

TEST(IoImage, ResizeAreaAveragesBlocksExactly) {
    const Image im = test::test_image(16, 8, 3);
    for (int f : {2, 4, 8}) {
        const Image small = resize_area(im, 16 / f, 8 / f);
        ASSERT_EQ(small.width, 16 / f);
        for (int y = 0; y < small.height; ++y)
            for (int x = 0; x < small.width; ++x)
                for (int c = 0; c < 3; ++c) {
                    double sum = 0;
                    for (int j = 0; j < f; ++j)
                        for (int i = 0; i < f; ++i) sum += im.at(x * f + i, y * f + j, c);
                    ASSERT_NEAR(small.at(x, y, c), sum / (f * f), 1e-6);
                }
    }
}

TEST(IoImage, ResizeAreaUnevenFactorPreservesMean) {
    const Image im = test::test_image(7, 5, 1);
    const Image small = resize_area(im, 3, 2);
    double mean_in = 0, mean_out = 0;
    for (float v : im.pixels) mean_in += v;
    for (float v : small.pixels) mean_out += v;
    EXPECT_NEAR(mean_in / 35.0, mean_out / 6.0, 1e-6);
    // The first output pixel covers 7/3 columns: columns 0, 1 fully, a third of column 2.
    const double row0 = (im.at(0, 0, 0) + im.at(1, 0, 0) + im.at(2, 0, 0) / 3.0) * 3.0 / 7.0;
    const double row1 = (im.at(0, 1, 0) + im.at(1, 1, 0) + im.at(2, 1, 0) / 3.0) * 3.0 / 7.0;
    const double row2 = (im.at(0, 2, 0) + im.at(1, 2, 0) + im.at(2, 2, 0) / 3.0) * 3.0 / 7.0;
    EXPECT_NEAR(small.at(0, 0, 0), (row0 + row1 + row2 * 0.5) / 2.5, 1e-6);
    const Image same = resize_area(Image(5, 3, 2, 0.25f), 2, 2);
    for (float v : same.pixels) EXPECT_NEAR(v, 0.25f, 1e-7);
}

TEST(IoImage, ToChannelsReplicatesGrayAndDropsAlpha) {
    Image ga(1, 1, 2);
    ga.pixels = {0.2f, 0.9f};
    const Image rgb = to_channels(ga, 3);
    EXPECT_EQ(rgb.pixels, (std::vector<float>{0.2f, 0.2f, 0.2f}));
    EXPECT_EQ(to_channels(ga, 4).pixels, (std::vector<float>{0.2f, 0.2f, 0.2f, 0.9f}));
    Image rgba(1, 1, 4);
    rgba.pixels = {0.1f, 0.2f, 0.3f, 0.4f};
    EXPECT_EQ(to_channels(rgba, 3).pixels, (std::vector<float>{0.1f, 0.2f, 0.3f}));
    EXPECT_EQ(to_channels(rgba, 1).pixels, (std::vector<float>{0.1f}));
}

TEST(IoImage, SrgbCurves) {
    EXPECT_NEAR(srgb_to_linear(0.5f), 0.2140411f, 1e-6f);
    EXPECT_NEAR(linear_to_srgb(0.2140411f), 0.5f, 1e-6f);
    EXPECT_NEAR(srgb_to_linear(0.04045f), 0.04045f / 12.92f, 1e-7f);
    EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
    EXPECT_NEAR(srgb_to_linear(1.0f), 1.0f, 1e-6f);
    for (int i = 0; i <= 100; ++i) {
        const float x = float(i) / 100.0f;
        EXPECT_NEAR(linear_to_srgb(srgb_to_linear(x)), x, 2e-6f);
    }
}

}  // namespace
}  // namespace lumigauss
