// COLMAP sparse models: text and binary round trips, the plaza model, and every error naming file and record.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <map>

#include "fast/io_test_util.h"
#include "lumigauss/io/colmap.h"

namespace lumigauss {
namespace {

using test::expect_error;
using test::TempDir;

// Cameras of several models, a name in a subfolder and one with a space, full-precision poses.
ColmapModel varied_model() {
    ColmapModel m = test::small_model(3, 40, 30);
    m.cameras[2] = ColmapCamera{2, "SIMPLE_RADIAL", 64, 48, {55.5, 32.25, 24.125, -0.0123456789}};
    m.cameras[7] =
        ColmapCamera{7, "OPENCV", 1280, 823, {1000.1, 999.9, 640.3, 411.7, 0.1, -0.01, 1e-4, -2e-5}};
    m.images[1].camera_id = 2;
    m.images[2].camera_id = 7;
    m.images[2].name = "sub dir/photo 3.JPG";
    m.images[0].qvec = {0.566043377, 0.561057985, -0.439914376, 0.413864940};
    m.images[0].tvec = {-7.876156123456789, 4.367409, 52.27627};
    m.images[1].qvec = {0.1, 0.2, 0.3, 1.0 / 3.0};
    for (int i = 0; i < 100; ++i) {
        m.point_xyz.push_back({float(i) * 0.1f, -float(i) / 3.0f, 1e-7f * float(i)});
        m.point_rgb.push_back({float(i % 256) / 255.0f, float(255 - i) / 255.0f, 0.0f});
    }
    // Structure from motion's extras: each point seen by one or two images, and a keypoint without a point.
    m.point_error.resize(m.point_xyz.size());
    m.point_tracks.resize(m.point_xyz.size());
    for (std::size_t p = 0; p < m.point_xyz.size(); ++p) {
        m.point_error[p] = 0.1 + double(p) / 7.0;
        for (std::size_t i = 0; i < m.images.size(); ++i) {
            if ((p + i) % 3 == 0) continue;
            ColmapImage& im = m.images[i];
            m.point_tracks[p].push_back({im.id, int(im.observations.size())});
            im.observations.push_back({{double(p) + 0.123456789, 29.5 - double(i) / 3.0}, std::int64_t(p)});
        }
    }
    m.images[0].observations.push_back({{1.0 / 3.0, 2.0}, -1});
    return m;
}

void expect_same_model(const ColmapModel& a, const ColmapModel& b) {
    EXPECT_EQ(a.cameras, b.cameras);
    ASSERT_EQ(a.images.size(), b.images.size());
    for (std::size_t i = 0; i < a.images.size(); ++i) {
        EXPECT_EQ(a.images[i].id, b.images[i].id);
        EXPECT_EQ(a.images[i].name, b.images[i].name);
        EXPECT_EQ(a.images[i].camera_id, b.images[i].camera_id);
        for (int k = 0; k < 4; ++k) EXPECT_EQ(a.images[i].qvec[k], b.images[i].qvec[k]);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(a.images[i].tvec[k], b.images[i].tvec[k]);
        EXPECT_EQ(a.images[i].observations, b.images[i].observations) << a.images[i].name;
    }
    EXPECT_EQ(a.point_error, b.point_error);
    EXPECT_EQ(a.point_tracks, b.point_tracks);
    ASSERT_EQ(a.point_xyz.size(), b.point_xyz.size());
    ASSERT_EQ(a.point_rgb.size(), b.point_rgb.size());
    for (std::size_t i = 0; i < a.point_xyz.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(a.point_xyz[i][k], b.point_xyz[i][k]);
            ASSERT_EQ(a.point_rgb[i][k], b.point_rgb[i][k]);
        }
}

TEST(ColmapModelTable, IdsNamesAndParameterCounts) {
    EXPECT_EQ(colmap_model_id("SIMPLE_PINHOLE"), 0);
    EXPECT_EQ(colmap_model_id("PINHOLE"), 1);
    EXPECT_EQ(colmap_model_id("OPENCV"), 4);
    EXPECT_EQ(colmap_model_name(2), "SIMPLE_RADIAL");
    EXPECT_EQ(colmap_model_name(6), "FULL_OPENCV");
    EXPECT_EQ(colmap_model_name(42), "");
    EXPECT_EQ(colmap_model_num_params("SIMPLE_PINHOLE"), 3);
    EXPECT_EQ(colmap_model_num_params("RADIAL"), 5);
    EXPECT_EQ(colmap_model_num_params("OPENCV"), 8);
    EXPECT_EQ(colmap_model_num_params("FULL_OPENCV"), 12);
    EXPECT_EQ(colmap_model_num_params("NOPE"), -1);
}

TEST(ColmapIo, TextRoundTripIsExact) {
    TempDir tmp;
    const ColmapModel m = varied_model();
    write_colmap_text(tmp / "model", m);
    EXPECT_EQ(find_colmap_format(tmp / "model"), ColmapFormat::Text);
    expect_same_model(read_colmap_text(tmp / "model"), m);
    expect_same_model(read_colmap(tmp / "model"), m);
}

TEST(ColmapIo, BinaryRoundTripIsExact) {
    TempDir tmp;
    const ColmapModel m = varied_model();
    write_colmap_binary(tmp / "model", m);
    EXPECT_EQ(find_colmap_format(tmp / "model"), ColmapFormat::Binary);
    expect_same_model(read_colmap_binary(tmp / "model"), m);
    EXPECT_FALSE(find_colmap_format(tmp.path().string()).has_value());
}

// Loading a scene reads poses and points only: the same model without observations, tracks and errors, in
// both forms, and a fault in the parts it skips does not stop it (they are not read).
TEST(ColmapIo, PosesAndPointsSkipObservationsAndTracks) {
    TempDir tmp;
    ColmapModel expected = varied_model();
    write_colmap_text(tmp / "t", expected);
    write_colmap_binary(tmp / "b", expected);
    for (ColmapImage& im : expected.images) im.observations.clear();
    expected.point_error.clear();
    expected.point_tracks.clear();
    expect_same_model(read_colmap_text(tmp / "t", ColmapContent::PosesAndPoints), expected);
    expect_same_model(read_colmap_binary(tmp / "b", ColmapContent::PosesAndPoints), expected);
    expect_same_model(read_colmap(tmp / "b", ColmapContent::PosesAndPoints), expected);

    // An odd token in a POINTS2D line and in a track: read in full they fail, poses and points still read.
    std::string images = test::read_text(tmp / "t/images.txt");
    images.replace(images.find("0.123456789"), 11, "x.123456789");
    test::write_text(tmp / "t/images.txt", images);
    expect_error([&] { read_colmap_text(tmp / "t"); }, {"images.txt", "x.123456789"});
    EXPECT_EQ(read_colmap_text(tmp / "t", ColmapContent::PosesAndPoints).images.size(),
              expected.images.size());
    std::string points = test::read_text(tmp / "t/points3D.txt");
    points.insert(points.find('\n', points.find("\n1 ")), " 7");  // an odd track
    test::write_text(tmp / "t/points3D.txt", points);
    EXPECT_EQ(read_colmap_text(tmp / "t", ColmapContent::PosesAndPoints).point_xyz.size(),
              expected.point_xyz.size());

    // A binary file cut inside the skipped part is still caught: its lengths are checked before skipping.
    std::string bin = test::read_text(tmp / "b/images.bin");
    bin.resize(bin.size() - 10);
    test::write_text(tmp / "b/images.bin", bin);
    expect_error([&] { read_colmap_binary(tmp / "b", ColmapContent::PosesAndPoints); },
                 {"images.bin", "truncated"});
}

TEST(ColmapIo, ReadsPlazaAndConvertsToBinary) {
    const std::string plaza = test::plaza_dir();
    if (plaza.empty()) GTEST_SKIP() << "shared data/plaza_mini not present";
    const ColmapModel m = read_colmap(plaza + "/sparse/0");
    ASSERT_EQ(m.cameras.size(), 28u);
    ASSERT_EQ(m.images.size(), 28u);
    EXPECT_EQ(m.point_xyz.size(), 4658u);
    const ColmapCamera& c1 = m.cameras.at(1);
    EXPECT_EQ(c1.model, "PINHOLE");
    EXPECT_EQ(c1.width, 128);
    EXPECT_EQ(c1.params, (std::vector<double>{100.853222, 100.853222, 64.0, 48.0}));
    EXPECT_EQ(m.images[0].name, "train_0000.png");
    EXPECT_EQ(m.images[0].qvec[0], 0.566043377);
    EXPECT_EQ(m.images[0].tvec[2], 52.276270);
    EXPECT_EQ(m.point_xyz[0][0], -4.1671f);
    EXPECT_EQ(m.point_rgb[0][0], 154.0f / 255.0f);
    // The data's tracks: each point is seen at least twice, and each track element names an observation of
    // that image which names the point back.
    ASSERT_EQ(m.point_tracks.size(), m.point_xyz.size());
    std::map<int, const ColmapImage*> image_by_id;
    for (const ColmapImage& im : m.images) image_by_id[im.id] = &im;
    for (std::size_t p = 0; p < m.point_tracks.size(); ++p) {
        ASSERT_GE(m.point_tracks[p].size(), 2u) << p;
        for (const ColmapTrackElement& e : m.point_tracks[p]) {
            const ColmapImage& im = *image_by_id.at(e.image_id);
            ASSERT_LT(std::size_t(e.observation), im.observations.size());
            ASSERT_EQ(im.observations[std::size_t(e.observation)].point_index, std::int64_t(p));
        }
    }
    TempDir tmp;
    write_colmap_binary(tmp / "bin", m);
    expect_same_model(read_colmap_binary(tmp / "bin"), m);
}

TEST(ColmapIo, TextWithoutObservationLineAtEndAndCommentsReads) {
    TempDir tmp;
    test::write_text(tmp / "m/cameras.txt", "# c\n\n1 SIMPLE_PINHOLE 10 8 12 5 4\r\n");
    test::write_text(tmp / "m/images.txt",
                     "# i\n1 1 0 0 0 0 0 1 1 a.png\n1.5 2.5 -1 3 4 7\n2 1 0 0 0 1 0 1 1 b.png");
    test::write_text(tmp / "m/points3D.txt", "# p\n5 1 2 3 255 0 10 0.5 1 0 2 1\n");
    const ColmapModel m = read_colmap_text(tmp / "m");
    EXPECT_EQ(m.images.size(), 2u);
    EXPECT_EQ(m.images[1].name, "b.png");
    EXPECT_EQ(m.cameras.at(1).params, (std::vector<double>{12, 5, 4}));
    EXPECT_EQ(m.point_rgb[0][2], 10.0f / 255.0f);
    // POINT3D_ID 5 is the first point; 7 is not in points3D (a hand-edited model): it belongs to none.
    ASSERT_EQ(m.images[0].observations.size(), 2u);
    EXPECT_EQ(m.images[0].observations[0], (ColmapObservation{{1.5, 2.5}, -1}));
    EXPECT_EQ(m.images[0].observations[1], (ColmapObservation{{3, 4}, -1}));
    EXPECT_EQ(m.point_error, std::vector<double>{0.5});
    EXPECT_EQ(m.point_tracks[0], (std::vector<ColmapTrackElement>{{1, 0}, {2, 1}}));
}

// Point ids need not be contiguous: observations are tied to points by id on disk, by index in memory, and
// written back numbered from 1.
TEST(ColmapIo, ObservationsFollowTheirPointsAcrossIds) {
    TempDir tmp;
    test::write_text(tmp / "m/cameras.txt", "1 SIMPLE_PINHOLE 10 8 12 5 4\n");
    test::write_text(tmp / "m/images.txt", "1 1 0 0 0 0 0 1 1 a.png\n1 1 90 2 2 40\n");
    test::write_text(tmp / "m/points3D.txt", "40 0 0 1 1 2 3 0.25 1 1\n90 1 0 1 4 5 6 0.5 1 0\n");
    const ColmapModel m = read_colmap_text(tmp / "m");
    EXPECT_EQ(m.images[0].observations[0].point_index, 1);
    EXPECT_EQ(m.images[0].observations[1].point_index, 0);
    write_colmap_binary(tmp / "b", m);
    expect_same_model(read_colmap_binary(tmp / "b"), m);
    write_colmap_text(tmp / "t", m);
    EXPECT_NE(test::read_text(tmp / "t/images.txt").find("\n1 1 2 2 2 1\n"), std::string::npos);
}

TEST(ColmapErrors, OptionalArraysOfTheWrongLengthAreNotWritten) {
    TempDir tmp;
    ColmapModel m = test::small_model(2, 8, 6);
    m.point_error = {0.5};
    expect_error([&] { write_colmap_text(tmp / "t", m); }, {"point_error holds 1 values for 3 points"});
    m.point_error.clear();
    m.point_tracks.resize(4);
    expect_error([&] { write_colmap_binary(tmp / "b", m); }, {"point_tracks holds 4 tracks for 3 points"});
    m.point_tracks.clear();
    m.images[1].observations.push_back({{1, 1}, 3});
    expect_error([&] { write_colmap_text(tmp / "t", m); }, {"img_1.png", "observes point 3 of 3"});
}

// --- errors: each names the file and the record or line ---

TEST(ColmapErrors, MissingFile) {
    TempDir tmp;
    write_colmap_text(tmp / "m", test::small_model(2, 8, 6));
    std::filesystem::remove(tmp / "m/points3D.txt");
    expect_error([&] { read_colmap_text(tmp / "m"); }, {"points3D.txt", "not found"});
    expect_error([&] { read_colmap(tmp / "m"); }, {tmp / "m", "no COLMAP model"});
}

TEST(ColmapErrors, TruncatedBinary) {
    TempDir tmp;
    write_colmap_binary(tmp / "m", test::small_model(3, 8, 6));
    std::string images = test::read_text(tmp / "m/images.bin");
    // A count that promises far more records than the file holds.
    std::string inflated = images;
    const std::uint64_t count = 1000;
    std::memcpy(inflated.data(), &count, sizeof count);
    test::write_text(tmp / "m/images.bin", inflated);
    expect_error([&] { read_colmap_binary(tmp / "m"); }, {"images.bin", "truncated", "1000"});
    // A file cut inside its last record.
    test::write_text(tmp / "m/images.bin", images.substr(0, images.size() - 5));
    expect_error([&] { read_colmap_binary(tmp / "m"); }, {"images.bin", "record 3 of 3", "truncated"});
    test::write_text(tmp / "m/images.bin", images);
    const std::string points = test::read_text(tmp / "m/points3D.bin");
    test::write_text(tmp / "m/points3D.bin", points.substr(0, 4));
    expect_error([&] { read_colmap_binary(tmp / "m"); }, {"points3D.bin", "truncated"});
}

// The lengths inside records (an image's observations, a point's track) are checked against the bytes left
// before anything is allocated for them: 2^40 observations in a 200-byte file must not reach the allocator.
TEST(ColmapErrors, BinaryLengthsInsideRecordsArePlausible) {
    TempDir tmp;
    write_colmap_binary(tmp / "m", test::small_model(1, 8, 6));
    const std::string images = test::read_text(tmp / "m/images.bin");
    std::string inflated = images;
    const std::uint64_t huge = std::uint64_t(1) << 40;
    std::memcpy(inflated.data() + inflated.size() - 8, &huge, sizeof huge);  // the only image's POINTS2D
    test::write_text(tmp / "m/images.bin", inflated);
    expect_error([&] { read_colmap_binary(tmp / "m"); }, {"images.bin", "record 1 of 1", "POINTS2D length"});
    test::write_text(tmp / "m/images.bin", images);
    std::string points = test::read_text(tmp / "m/points3D.bin");
    std::memcpy(points.data() + points.size() - 8, &huge, sizeof huge);  // the last point's track
    test::write_text(tmp / "m/points3D.bin", points);
    expect_error([&] { read_colmap_binary(tmp / "m"); }, {"points3D.bin", "record 3 of 3", "TRACK length"});
}

// cameras.bin stores width and height as uint64: 2^32 + 40 was cast to int and read as 40.
TEST(ColmapErrors, WrappedImageSizeInBinaryCameras) {
    TempDir tmp;
    write_colmap_binary(tmp / "m", test::small_model(3, 40, 30));
    std::string cameras = test::read_text(tmp / "m/cameras.bin");
    const std::uint64_t wrapped = (std::uint64_t(1) << 32) + 40;
    std::memcpy(cameras.data() + 8 + 4 + 4, &wrapped, sizeof wrapped);  // count, id, model, then width
    test::write_text(tmp / "m/cameras.bin", cameras);
    expect_error([&] { read_colmap_binary(tmp / "m"); }, {"cameras.bin", "record 1 of", "width 4294967336"});
}

// A cut images.txt gave 5 of 10 views (the test views vanished) and a cut points3D.txt 81 of 219 points,
// silently. COLMAP's "# Number of ..." header now says how many records there must be.
TEST(ColmapErrors, TextCutAtALineBoundaryIsRefused) {
    for (const char* file : {"cameras.txt", "images.txt", "points3D.txt"}) {
        TempDir tmp;
        write_colmap_text(tmp / "m", test::small_model(3, 8, 6));
        const std::string path = tmp / (std::string("m/") + file);
        const std::string text = test::read_text(path);
        const std::size_t cut = text.rfind('\n', text.size() - 2);  // drop the last line
        const std::size_t keep = std::string(file) == "images.txt" ? text.rfind('\n', cut - 1) : cut;
        test::write_text(path, text.substr(0, keep + 1));
        expect_error([&] { (void)read_colmap_text(tmp / "m"); }, {file, "declares", "cut short"});
    }
}

TEST(ColmapErrors, ImageWithUnknownCameraId) {
    TempDir tmp;
    ColmapModel m = test::small_model(3, 8, 6);
    m.images[1].camera_id = 99;
    write_colmap_text(tmp / "t", m);
    expect_error([&] { read_colmap_text(tmp / "t"); }, {"images.txt", "line 7", "camera_id 99", "img_1.png"});
    write_colmap_binary(tmp / "b", m);
    expect_error([&] { read_colmap_binary(tmp / "b"); }, {"images.bin", "record 2 of 3", "camera_id 99"});
}

TEST(ColmapErrors, MalformedTextLine) {
    TempDir tmp;
    write_colmap_text(tmp / "m", test::small_model(2, 8, 6));
    std::string images = test::read_text(tmp / "m/images.txt");
    images.replace(images.find(" 1 0 0 0 "), 9, " 1 zero 0 0 ");
    test::write_text(tmp / "m/images.txt", images);
    expect_error([&] { read_colmap_text(tmp / "m"); }, {"images.txt", "line 5", "'zero'"});
    test::write_text(tmp / "m/cameras.txt", "1 PINHOLE 8 6 1 2 3\n");
    expect_error([&] { read_colmap_text(tmp / "m"); }, {"cameras.txt", "line 1", "4 parameters, found 3"});
    test::write_text(tmp / "m/cameras.txt", "# x\n1 PINHOLE 8\n");
    expect_error([&] { read_colmap_text(tmp / "m"); }, {"cameras.txt", "line 2"});
    test::write_text(tmp / "m/cameras.txt", "1 MYSTERY 8 6 1 2 3\n");
    expect_error([&] { read_colmap_text(tmp / "m"); },
                 {"cameras.txt", "line 1", "unknown camera model 'MYSTERY'"});
}

TEST(ColmapErrors, NonFinitePose) {
    TempDir tmp;
    ColmapModel m = test::small_model(3, 8, 6);
    m.images[2].tvec.y = std::numeric_limits<double>::quiet_NaN();
    write_colmap_text(tmp / "t", m);
    expect_error([&] { read_colmap_text(tmp / "t"); }, {"images.txt", "line 9", "img_2.png", "NaN or Inf"});
    write_colmap_binary(tmp / "b", m);
    expect_error([&] { read_colmap_binary(tmp / "b"); }, {"images.bin", "record 3 of 3", "NaN or Inf"});
    m.images[2].tvec.y = 0;
    m.images[0].qvec.z = std::numeric_limits<double>::infinity();
    write_colmap_binary(tmp / "b", m);
    expect_error([&] { read_colmap_binary(tmp / "b"); }, {"images.bin", "record 1 of 3", "NaN or Inf"});
}

TEST(ColmapErrors, UnknownCameraModelId) {
    TempDir tmp;
    write_colmap_binary(tmp / "m", test::small_model(2, 8, 6));
    std::string cameras = test::read_text(tmp / "m/cameras.bin");
    // Second record: after the count (8) and the first record (4 + 4 + 8 + 8 + 4 * 8 bytes), id then model
    // id.
    const std::int32_t bad_model = 42;
    std::memcpy(cameras.data() + 8 + 56 + 4, &bad_model, sizeof bad_model);
    test::write_text(tmp / "m/cameras.bin", cameras);
    expect_error([&] { read_colmap_binary(tmp / "m"); },
                 {"cameras.bin", "record 2 of 2", "unknown camera model id 42"});
}

}  // namespace
}  // namespace lumigauss
