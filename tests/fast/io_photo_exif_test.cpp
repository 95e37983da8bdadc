// EXIF: the TIFF structure (both byte orders), finding the block in JPEG and PNG files, damaged blocks, the
// eight orientations, and how a scene uses them (photos turned upright only when their camera says so).
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "fast/io_test_util.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/exif_notes.h"
#include "lumigauss/io/image_orientation.h"
#include "lumigauss/io/photo_exif.h"
#include "lumigauss/model/scene_record.h"
#include "support/run_cli.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using test::expect_error;
using test::TempDir;
using Bytes = std::vector<std::uint8_t>;

// A TIFF block written field by field, in either byte order, the way cameras lay it out: header, IFD0
// (Orientation, the Exif IFD pointer), the Exif IFD (ExposureTime, FNumber, ISO), then the rationals.
class TiffWriter {
  public:
    explicit TiffWriter(bool little) : little_(little) {}

    struct Tag {
        std::uint16_t tag, type;
        std::uint32_t count, value;
    };

    void u16(unsigned v) {
        const unsigned lo = v & 0xFF, hi = (v >> 8) & 0xFF;
        little_ ? (put(lo), put(hi)) : (put(hi), put(lo));
    }
    void u32(std::uint32_t v) {
        const unsigned lo = v & 0xFFFF, hi = v >> 16;
        little_ ? (u16(lo), u16(hi)) : (u16(hi), u16(lo));
    }
    void header(std::uint32_t first_ifd) {
        put(little_ ? 'I' : 'M'), put(little_ ? 'I' : 'M'), u16(42), u32(first_ifd);
    }
    // A SHORT value sits in the first two bytes of the value field, whatever the byte order.
    void ifd(const std::vector<Tag>& tags) {
        u16(std::uint16_t(tags.size()));
        for (const Tag& t : tags) {
            u16(t.tag), u16(t.type), u32(t.count);
            if (t.type == 3 && t.count == 1)
                u16(t.value), u16(0);
            else
                u32(t.value);
        }
        u32(0);  // no next IFD
    }
    std::size_t size() const { return bytes.size(); }

    Bytes bytes;

  private:
    void put(unsigned v) { bytes.push_back(std::uint8_t(v)); }
    bool little_;
};

// orientation 6, 1/250 s, f/5.6, ISO 200.
Bytes camera_block(bool little, std::uint16_t orientation = 6) {
    TiffWriter w(little);
    w.header(8);
    // IFD0 at 8: 2 entries -> 2 + 24 + 4 = 30 bytes; Exif IFD at 38: 3 entries -> 42 bytes; rationals at 80.
    w.ifd({{0x0112, 3, 1, orientation}, {0x8769, 4, 1, 38}});
    w.ifd({{0x829A, 5, 1, 80}, {0x829D, 5, 1, 88}, {0x8827, 3, 1, 200}});
    EXPECT_EQ(w.size(), 80u);
    w.u32(1), w.u32(250), w.u32(56), w.u32(10);
    return w.bytes;
}

TEST(PhotoExif, ReadsOrientationAndExposureInBothByteOrders) {
    for (bool little : {true, false}) {
        const PhotoExif e = parse_exif_tiff(camera_block(little), "block");
        EXPECT_EQ(e.orientation, 6);
        ASSERT_TRUE(e.has_exposure());
        EXPECT_DOUBLE_EQ(*e.exposure_time_s, 1.0 / 250);
        EXPECT_DOUBLE_EQ(*e.f_number, 5.6);
        EXPECT_DOUBLE_EQ(*e.iso, 200);
        // EV100 = log2(5.6^2 * 250) - log2(200 / 100) = log2(7840) - 1
        EXPECT_NEAR(*e.ev100(), std::log2(7840.0) - 1.0, 1e-12);
        EXPECT_TRUE(e.problem.empty());
    }
}

TEST(PhotoExif, OutOfRangeOrientationAndMissingExposureAreUnknown) {
    for (int bad : {0, 9, 65535})
        EXPECT_EQ(parse_exif_tiff(camera_block(true, std::uint16_t(bad)), "b").orientation, 1);
    TiffWriter w(true);
    w.header(8);
    w.ifd({{0x0112, 3, 1, 3}});
    const PhotoExif e = parse_exif_tiff(w.bytes, "b");
    EXPECT_EQ(e.orientation, 3);
    EXPECT_FALSE(e.has_exposure());
    EXPECT_FALSE(e.ev100());
    PhotoExif no_iso;
    no_iso.exposure_time_s = 1.0, no_iso.f_number = 1.0;
    EXPECT_DOUBLE_EQ(*no_iso.ev100(), 0.0) << "ISO 100 when unknown";
}

TEST(PhotoExif, DamagedBlocksAreRefusedNamingTheSource) {
    Bytes block = camera_block(true);
    expect_error([&] { parse_exif_tiff(Bytes(block.begin(), block.begin() + 6), "a.jpg"); },
                 {"a.jpg", "8-byte"});
    Bytes bad_mark = block;
    bad_mark[0] = 'X';
    expect_error([&] { parse_exif_tiff(bad_mark, "a.jpg"); }, {"a.jpg", "byte-order"});
    Bytes far_ifd = block;
    far_ifd[4] = 0xF0;  // IFD0 offset 0xF0 in a 96-byte block
    expect_error([&] { parse_exif_tiff(far_ifd, "a.jpg"); }, {"a.jpg", "outside"});
    Bytes cut = Bytes(block.begin(), block.begin() + 84);  // the FNumber rational cut off
    expect_error([&] { parse_exif_tiff(cut, "a.jpg"); }, {"a.jpg", "outside"});
    // A count of 2^32 - 1 rationals: past the block, refused before anything is read or allocated.
    TiffWriter w(true);
    w.header(8);
    w.ifd({{0x0112, 5, 0xFFFFFFFFu, 8}});
    expect_error([&] { parse_exif_tiff(w.bytes, "a.jpg"); }, {"outside"});
}

// JPEG: SOI, an APP0, an APP1 holding XMP (skipped), the APP1 "Exif", then the scan.
Bytes jpeg_with(const Bytes& tiff) {
    Bytes f = {0xFF, 0xD8, 0xFF, 0xE0, 0, 7, 'J', 'F', 'I', 'F', 0};
    const std::string xmp = "http://ns.adobe.com/xap/1.0/";
    f.insert(f.end(), {0xFF, 0xE1, 0, std::uint8_t(xmp.size() + 2)});
    f.insert(f.end(), xmp.begin(), xmp.end());
    const std::size_t length = tiff.size() + 8;
    f.insert(f.end(), {0xFF, 0xFF, 0xE1, std::uint8_t(length >> 8), std::uint8_t(length & 0xFF), 'E', 'x',
                       'i', 'f', 0, 0});
    f.insert(f.end(), tiff.begin(), tiff.end());
    f.insert(f.end(), {0xFF, 0xDA, 0, 2, 0x12, 0x34, 0xFF, 0xD9});
    return f;
}

void write_bytes(const std::string& path, const Bytes& bytes) {
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

Bytes read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The PNG at `path` with an eXIf chunk holding `tiff` inserted after IHDR (CRC included).
void add_png_exif(const std::string& path, const Bytes& tiff) {
    Bytes png = read_bytes(path);
    ASSERT_GT(png.size(), 33u);
    Bytes chunk;
    const auto be32 = [&](std::uint32_t v) {
        for (int s = 24; s >= 0; s -= 8) chunk.push_back(std::uint8_t(v >> s));
    };
    be32(std::uint32_t(tiff.size()));
    chunk.insert(chunk.end(), {'e', 'X', 'I', 'f'});
    chunk.insert(chunk.end(), tiff.begin(), tiff.end());
    be32(std::uint32_t(crc32(0, chunk.data() + 4, uInt(chunk.size() - 4))));
    png.insert(png.begin() + 33, chunk.begin(), chunk.end());  // 8 signature + 25 IHDR
    write_bytes(path, png);
}

TEST(PhotoExif, FoundInJpegAndPngFiles) {
    TempDir tmp;
    write_bytes(tmp / "a.jpg", jpeg_with(camera_block(false)));
    PhotoExif e = read_photo_exif(tmp / "a.jpg");
    EXPECT_EQ(e.orientation, 6);
    EXPECT_DOUBLE_EQ(*e.f_number, 5.6);
    write_png(tmp / "b.png", test::test_image(5, 4, 3));
    EXPECT_EQ(read_photo_exif(tmp / "b.png").orientation, 1) << "no eXIf chunk";
    add_png_exif(tmp / "b.png", camera_block(true));
    e = read_photo_exif(tmp / "b.png");
    EXPECT_EQ(e.orientation, 6);
    EXPECT_DOUBLE_EQ(*e.iso, 200);
    EXPECT_EQ(read_image(tmp / "b.png").width, 5) << "the chunk leaves the PNG readable";
    test::write_text(tmp / "c.hdr", "#?RADIANCE\n");
    EXPECT_FALSE(read_photo_exif(tmp / "c.hdr").has_exposure());
    EXPECT_THROW(read_photo_exif(tmp / "missing.jpg"), Error);
}

TEST(PhotoExif, DamagedExifInAFileIsAWarningNotARefusal) {
    TempDir tmp;
    Bytes block = camera_block(true);
    block[4] = 0xF0;
    write_bytes(tmp / "a.jpg", jpeg_with(block));
    const PhotoExif e = read_photo_exif(tmp / "a.jpg");
    EXPECT_EQ(e.orientation, 1);
    EXPECT_FALSE(e.has_exposure());
    EXPECT_NE(e.problem.find("a.jpg"), std::string::npos) << e.problem;
    Bytes cut = jpeg_with(camera_block(true));
    cut.resize(40);
    write_bytes(tmp / "b.jpg", cut);
    EXPECT_NE(read_photo_exif(tmp / "b.jpg").problem.find("ends"), std::string::npos);
    EXPECT_THROW(parse_photo_exif(cut, "b.jpg"), Error);
}

// A 3 x 2 image whose pixel (x, y) holds 10 y + x, turned by every orientation (EXIF 2.32's table).
TEST(ImageOrientation, TheEightOrientations) {
    Image stored(3, 2, 1);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) stored.at(x, y, 0) = float(10 * y + x);
    const std::vector<std::vector<float>> expected = {
        {0, 1, 2, 10, 11, 12},  // 1
        {2, 1, 0, 12, 11, 10},  // 2 mirrored left-right
        {12, 11, 10, 2, 1, 0},  // 3 turned 180
        {10, 11, 12, 0, 1, 2},  // 4 mirrored top-bottom
        {0, 10, 1, 11, 2, 12},  // 5 transposed
        {10, 0, 11, 1, 12, 2},  // 6 turned 90 clockwise
        {12, 2, 11, 1, 10, 0},  // 7 transversed
        {2, 12, 1, 11, 0, 10},  // 8 turned 90 anticlockwise
    };
    for (int o = 1; o <= 8; ++o) {
        const Image up = upright_image(stored, o);
        EXPECT_EQ(up.width, o >= 5 ? 2 : 3) << o;
        EXPECT_EQ(up.pixels, expected[std::size_t(o - 1)]) << "orientation " << o;
    }
    EXPECT_EQ(upright_image(upright_image(stored, 6), 8).pixels, stored.pixels);
    EXPECT_EQ(upright_image(stored, 0).pixels, stored.pixels);
}

// A scene of three 8 x 6 photos: img_0 stored turned (6 x 8) with tag 6 and a mask of the stored size, img_1
// stored upright with tag 6 (COLMAP's case: used as stored), img_2 without EXIF.
TEST(PhotoExifScene, PhotosTurnUprightOnlyWhenTheirCameraSaysSo) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(3, 8, 6));
    const Image upright = test::test_image(8, 6, 3);
    write_png(tmp / "images/img_0.png", upright_image(upright, 8));  // stored 6 x 8
    add_png_exif(tmp / "images/img_0.png", camera_block(true, 6));
    add_png_exif(tmp / "images/img_1.png", camera_block(false, 6));
    fs::create_directories(tmp.path() / "masks");
    Image mask(8, 6, 1, 0.0f);
    mask.at(1, 0, 0) = 1.0f;
    write_png(tmp / "masks/img_0.png", upright_image(mask, 8));  // the stored photo's size
    write_png(tmp / "masks/img_1.png", mask);

    const Dataset d = load_dataset(tmp.path().string());
    EXPECT_EQ(d.photos_turned_upright, 1u);
    EXPECT_EQ(d.orientation_tags_not_applied, 1u);
    EXPECT_EQ(d.views[0].image_orientation, 6);
    EXPECT_EQ(d.views[0].mask_orientation, 6);
    EXPECT_EQ(d.views[1].image_orientation, 1);
    EXPECT_EQ(d.load_image(d.views[0]).pixels, upright.pixels);
    EXPECT_EQ(d.load_mask(d.views[0]).pixels, mask.pixels);
    EXPECT_EQ(d.load_image(d.views[1]).pixels, upright.pixels);
    EXPECT_EQ(d.load_mask(d.views[1]).pixels, mask.pixels);
    const Dataset half = load_dataset(tmp.path().string(), {.downscale = 2});
    EXPECT_EQ(half.load_image(half.views[0]).width, 4);

    const std::vector<std::string> notes = exif_notes(d);
    ASSERT_EQ(notes.size(), 3u);
    EXPECT_NE(notes[0].find("1 photo turned upright"), std::string::npos) << notes[0];
    EXPECT_NE(notes[2].find("2 of 3 photos"), std::string::npos) << notes[2];

    // The run's scene record logs each photo's EXIF.
    save_scene_record(tmp / "scene.json", scene_record_of(d));
    const SceneRecord r = *load_scene_record(tmp / "scene.json");
    EXPECT_TRUE(r.photos[0].turned_upright);
    EXPECT_FALSE(r.photos[1].turned_upright);
    EXPECT_EQ(r.photos[1].exif.orientation, 6);
    EXPECT_DOUBLE_EQ(*r.photos[0].exif.exposure_time_s, 1.0 / 250);
    EXPECT_FALSE(r.photos[2].exif.f_number);

    // A stored photo that fits its camera neither way names the orientation in the error.
    write_png(tmp / "images/img_0.png", test::test_image(6, 7, 3));
    add_png_exif(tmp / "images/img_0.png", camera_block(true, 6));
    expect_error([&] { load_dataset(tmp.path().string()); }, {"img_0.png", "6x7", "8x6"});
}

// `lumigauss info --photos`: one line per photo with what its EXIF said and what was done with it.
TEST(CliInfoExif, PhotosListsEachPhotosExif) {
    TempDir tmp;
    const fs::path scene = tmp.path() / "scene";
    test::write_scene(scene, test::small_model(3, 8, 6));
    write_png((scene / "images/img_0.png").string(), upright_image(test::test_image(8, 6, 3), 8));
    add_png_exif((scene / "images/img_0.png").string(), camera_block(true, 6));
    add_png_exif((scene / "images/img_1.png").string(), camera_block(false, 6));
    const testing::CommandResult r =
        testing::run_lumigauss("info " + testing::shell_quoted(scene.string()) + " --photos", tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("exif:          1 photo turned upright"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("EV100 11.94 to 11.94"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("img_0.png  test  8x6  6 (turned upright)  1/250 s  f/5.6  200  11.94"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("img_1.png  train  8x6  6 (as stored)  1/250 s  f/5.6  200  11.94"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("img_2.png  train  8x6  1  -  -  -  -"), std::string::npos) << r.output;
    const testing::CommandResult plain =
        testing::run_lumigauss("info " + testing::shell_quoted(scene.string()), tmp);
    EXPECT_EQ(plain.output.find("img_0.png"), std::string::npos) << "one line per photo only with --photos";
}

}  // namespace
}  // namespace lumigauss
