// Scenes on disk: the plaza COLMAP scene, downscaling, splits, masks, NeRF-OSR layout, and every loader
// error.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>

#include "fast/io_test_util.h"
#include "lumigauss/io/colmap.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/ply.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using test::expect_error;
using test::TempDir;

Vec2<double> project(const Camera& c, Vec3d world) {
    const Vec3d p = c.world_to_camera(world);
    return {c.fx * p.x / p.z + c.cx, c.fy * p.y / p.z + c.cy};
}

const View& view_named(const Dataset& d, const std::string& name) {
    for (const View& v : d.views)
        if (v.name == name) return v;
    throw std::runtime_error("no view " + name);
}

void expect_same_camera(const Camera& a, const Camera& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.fx, b.fx);
    EXPECT_EQ(a.fy, b.fy);
    EXPECT_EQ(a.cx, b.cx);
    EXPECT_EQ(a.cy, b.cy);
    for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(a.translation[i], b.translation[i]);
        for (int j = 0; j < 3; ++j) EXPECT_EQ(a.rotation(i, j), b.rotation(i, j));
    }
}

// --- the shared plaza scene ---

class DatasetPlaza : public ::testing::Test {
  protected:
    void SetUp() override {
        plaza_ = test::plaza_dir();
        if (plaza_.empty()) GTEST_SKIP() << "shared data/plaza_mini not present";
    }
    std::string plaza_;
};

TEST_F(DatasetPlaza, CountsSplitsMasksAndPoints) {
    const Dataset d = load_dataset(plaza_);
    EXPECT_EQ(d.format, "colmap-text");
    ASSERT_EQ(d.views.size(), 28u);
    EXPECT_EQ(d.split(Split::Train).size(), 24u);
    EXPECT_EQ(d.split(Split::Test).size(), 4u);
    EXPECT_EQ(d.split(Split::Validation).size(), 0u);
    for (const View* v : d.split(Split::Test)) EXPECT_EQ(v->name.substr(0, 5), "test_");
    for (const View& v : d.views) {
        EXPECT_EQ(fs::path(v.mask_path), fs::path(plaza_) / "masks" / v.name);
        EXPECT_EQ(v.camera_model, "PINHOLE");
    }
    EXPECT_EQ(d.point_xyz.size(), 4658u);
    EXPECT_EQ(d.point_rgb.size(), 4658u);
    EXPECT_TRUE(std::is_sorted(d.views.begin(), d.views.end(),
                               [](const View& a, const View& b) { return a.name < b.name; }));
}

TEST_F(DatasetPlaza, CamerasAgreeWithMetaJson) {
    const Dataset d = load_dataset(plaza_);
    const auto meta = nlohmann::json::parse(test::read_text(plaza_ + "/meta.json"));
    ASSERT_EQ(meta["images"].size(), 28u);
    for (const auto& m : meta["images"]) {
        const View& v = view_named(d, m["name"]);
        EXPECT_EQ(split_name(v.split),
                  m["split"].get<std::string>() == "train" ? std::string("train") : "test");
        EXPECT_EQ(v.camera.width, m["width"].get<int>());
        EXPECT_EQ(v.camera.height, m["height"].get<int>());
        EXPECT_NEAR(v.camera.fx, m["fx"].get<double>(), 1e-5);
        EXPECT_NEAR(v.camera.fy, m["fy"].get<double>(), 1e-5);
        EXPECT_NEAR(v.camera.cx, m["cx"].get<double>(), 1e-9);
        EXPECT_NEAR(v.camera.cy, m["cy"].get<double>(), 1e-9);
        // meta.json's c2w is the inverse of the COLMAP pose: R^T and the camera centre.
        const auto& c2w = m["c2w"];
        const Vec3d centre = v.camera.center();
        for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(centre[i], c2w[i][3].get<double>(), 1e-4);
            for (int j = 0; j < 3; ++j) EXPECT_NEAR(v.camera.rotation(j, i), c2w[i][j].get<double>(), 1e-6);
        }
    }
}

TEST_F(DatasetPlaza, LoadsImagesAndMasks) {
    const Dataset d = load_dataset(plaza_);
    const View& v = view_named(d, "train_0003.png");
    const Image image = d.load_image(v), mask = d.load_mask(v);
    EXPECT_EQ(image.width, 128);
    EXPECT_EQ(image.height, 96);
    EXPECT_EQ(image.channels, 3);
    EXPECT_EQ(image.pixels, read_image(v.image_path).pixels);
    EXPECT_EQ(mask.channels, 1);
    EXPECT_EQ(mask.width, 128);
    for (float m : mask.pixels) ASSERT_TRUE(m >= 0.0f && m <= 1.0f);
}

TEST_F(DatasetPlaza, DownscaleHalvesSizesAndProjections) {
    const Dataset full = load_dataset(plaza_);
    for (int f : {2, 4, 8}) {
        const Dataset small = load_dataset(plaza_, {.downscale = f});
        EXPECT_EQ(small.downscale, f);
        ASSERT_EQ(small.views.size(), full.views.size());
        for (std::size_t i = 0; i < full.views.size(); ++i) {
            const Camera& a = full.views[i].camera;
            const Camera& b = small.views[i].camera;
            EXPECT_EQ(b.width, 128 / f);
            EXPECT_EQ(b.height, 96 / f);
            EXPECT_EQ(small.views[i].source_width, 128);
            for (std::size_t p = 0; p < full.point_xyz.size(); p += 500) {
                const Vec3d x = full.point_xyz[p].cast<double>();
                const Vec2<double> ua = project(a, x), ub = project(b, x);
                EXPECT_NEAR(ub.x, ua.x / f, 1e-9);
                EXPECT_NEAR(ub.y, ua.y / f, 1e-9);
            }
        }
    }
    const Dataset half = load_dataset(plaza_, {.downscale = 2});
    const Image image = half.load_image(half.views[5]), mask = half.load_mask(half.views[5]);
    EXPECT_EQ(image.width, 64);
    EXPECT_EQ(image.height, 48);
    EXPECT_EQ(mask.width, 64);
    EXPECT_EQ(image.pixels, resize_area(full.load_image(full.views[5]), 64, 48).pixels);
}

TEST_F(DatasetPlaza, BinaryConversionLoadsTheSameDataset) {
    TempDir tmp;
    write_colmap_binary(tmp / "sparse/0", read_colmap_text(plaza_ + "/sparse/0"));
    fs::create_directory_symlink(fs::path(plaza_) / "images", tmp.path() / "images");
    fs::create_directory_symlink(fs::path(plaza_) / "masks", tmp.path() / "masks");
    fs::copy_file(fs::path(plaza_) / "split.csv", tmp.path() / "split.csv");
    const Dataset text = load_dataset(plaza_), binary = load_dataset(tmp.path().string());
    EXPECT_EQ(binary.format, "colmap-binary");
    ASSERT_EQ(binary.views.size(), text.views.size());
    for (std::size_t i = 0; i < text.views.size(); ++i) {
        EXPECT_EQ(binary.views[i].name, text.views[i].name);
        EXPECT_EQ(binary.views[i].split, text.views[i].split);
        EXPECT_EQ(fs::path(binary.views[i].mask_path).filename(),
                  fs::path(text.views[i].mask_path).filename());
        expect_same_camera(binary.views[i].camera, text.views[i].camera);
    }
    ASSERT_EQ(binary.point_xyz.size(), text.point_xyz.size());
    for (std::size_t i = 0; i < text.point_xyz.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(binary.point_xyz[i][k], text.point_xyz[i][k]);
            ASSERT_EQ(binary.point_rgb[i][k], text.point_rgb[i][k]);
        }
}

// --- synthetic COLMAP scenes ---

TEST(DatasetColmap, HoldoutEveryEighthImageWithoutSplitFile) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(10, 8, 6));
    const Dataset d = load_dataset(tmp.path().string());
    ASSERT_EQ(d.views.size(), 10u);
    const auto test_views = d.split(Split::Test);
    ASSERT_EQ(test_views.size(), 2u);
    EXPECT_EQ(test_views[0]->name, "img_0.png");
    EXPECT_EQ(test_views[1]->name, "img_8.png");
    EXPECT_EQ(load_dataset(tmp.path().string(), {.holdout_every = 3}).split(Split::Test).size(), 4u);
    EXPECT_EQ(load_dataset(tmp.path().string(), {.holdout_every = 0}).split(Split::Test).size(), 0u);
}

// A photo smaller than its camera with the same aspect ratio (a downscaled copy, as in an images_2/ folder)
// gets its camera scaled to it; another aspect ratio is still an error naming both sizes.
TEST(DatasetColmap, PhotosSmallerThanTheirCameraScaleIt) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(3, 40, 30));
    write_png(tmp / "images/img_1.png", test::test_image(20, 15, 3));  // half size
    write_png(tmp / "images/img_2.png", test::test_image(13, 10, 3));  // 40x30 / 3, rounded
    const Dataset d = load_dataset(tmp.path().string());
    EXPECT_EQ(d.cameras_fitted_to_photos, 2u);
    const Camera& half = d.views[1].camera;
    EXPECT_EQ(half.width, 20);
    EXPECT_EQ(half.height, 15);
    EXPECT_DOUBLE_EQ(half.fx, 21.0 / 2);  // small_model: fx = 20 + i
    EXPECT_DOUBLE_EQ(half.cx, 10.0);
    EXPECT_EQ(d.load_image(d.views[1]).width, 20);
    const Dataset quarter = load_dataset(tmp.path().string(), {.downscale = 2});
    EXPECT_EQ(quarter.views[1].camera.width, 10) << "-r applies after the fit";
    EXPECT_EQ(quarter.load_image(quarter.views[1]).width, 10);
    write_png(tmp / "images/img_1.png", test::test_image(20, 10, 3));  // another aspect ratio
    expect_error([&] { load_dataset(tmp.path().string()); }, {"img_1.png", "20x10", "40x30"});
}

// train --test-every N / --no-test: the override wins over a split file.
TEST(DatasetColmap, TestEveryOverridesTheSplitFile) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(10, 8, 6));
    std::string split = "filename;split\n";
    for (int i = 0; i < 10; ++i)
        split += "img_" + std::to_string(i) + ".png;" + (i < 5 ? "test" : "train") + "\n";
    test::write_text(tmp / "split.csv", split);
    EXPECT_EQ(load_dataset(tmp.path().string()).split(Split::Test).size(), 5u);
    const Dataset every3 = load_dataset(tmp.path().string(), {.test_every = 3});
    ASSERT_EQ(every3.split(Split::Test).size(), 4u);  // img_0, img_3, img_6, img_9
    EXPECT_EQ(every3.split(Split::Test)[1]->name, "img_3.png");
    EXPECT_EQ(load_dataset(tmp.path().string(), {.test_every = 0}).split(Split::Train).size(), 10u);
    EXPECT_THROW(load_dataset(tmp.path().string(), {.test_every = -1}), Error);
}

TEST(DatasetColmap, PoseAndIntrinsicsFromModel) {
    TempDir tmp;
    ColmapModel m = test::small_model(2, 8, 6);
    m.images[1].qvec = {2, 0, 0, 2};  // not unit: normalised to a 90 degree turn about z
    m.cameras[1] = ColmapCamera{1, "SIMPLE_PINHOLE", 8, 6, {30, 4.5, 2.5}};
    test::write_scene(tmp.path(), m, true);
    const Dataset d = load_dataset(tmp.path().string());
    EXPECT_EQ(d.format, "colmap-binary");
    const Camera& a = d.views[0].camera;
    EXPECT_EQ(a.fx, 30);
    EXPECT_EQ(a.fy, 30);
    EXPECT_EQ(a.cx, 4.5);
    EXPECT_EQ(a.cy, 2.5);
    const Camera& b = d.views[1].camera;
    EXPECT_EQ(b.fx, 21);
    const Vec3d turned = b.rotation * Vec3d{1, 0, 0};
    EXPECT_NEAR(turned.x, 0, 1e-12);
    EXPECT_NEAR(turned.y, 1, 1e-12);
    EXPECT_EQ(b.translation.x, -1);
    EXPECT_EQ(b.translation.z, 5);
    EXPECT_TRUE(d.views[0].mask_path.empty());
    const Image ones = d.load_mask(d.views[0]);
    EXPECT_EQ(ones.channels, 1);
    EXPECT_EQ(ones.pixels, std::vector<float>(48, 1.0f));
}

TEST(DatasetColmap, SplitFileAndMaskNaming) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(4, 8, 6));
    test::write_text(tmp / "scene_split.csv",
                     "filename;split\nimg_0.png;train\nimg_1.png; val\nimg_2.png;TEST\n"
                     "img_3.png;validation\nnot_registered.png;train\n");
    fs::create_directories(tmp.path() / "masks");
    write_png(tmp / "masks/img_0.png", Image(8, 6, 1, 1.0f));
    write_png(tmp / "masks/img_1.png.png", Image(8, 6, 1, 0.0f));  // COLMAP's naming
    write_png(tmp / "masks/img_2.jpg", Image(8, 6, 3, 0.0f));      // any image extension (content is PNG)
    const Dataset d = load_dataset(tmp.path().string());
    EXPECT_EQ(d.views[0].split, Split::Train);
    EXPECT_EQ(d.views[1].split, Split::Validation);
    EXPECT_EQ(d.views[2].split, Split::Test);
    EXPECT_EQ(d.views[3].split, Split::Validation);
    EXPECT_EQ(fs::path(d.views[0].mask_path).filename(), "img_0.png");
    EXPECT_EQ(fs::path(d.views[1].mask_path).filename(), "img_1.png.png");
    EXPECT_EQ(fs::path(d.views[2].mask_path).filename(), "img_2.jpg");
    EXPECT_TRUE(d.views[3].mask_path.empty());
    EXPECT_EQ(d.load_mask(d.views[2]).channels, 1);

    test::write_text(tmp / "scene_split.csv", "img_0.png;train\nimg_1.png;train\nimg_2.png;test\n");
    expect_error([&] { load_dataset(tmp.path().string()); }, {"scene_split.csv", "img_3.png", "not listed"});
    // A listed test photo the model lacks: its views vanished from every score (a cut images.txt).
    test::write_text(tmp / "scene_split.csv",
                     "img_0.png;train\nimg_1.png;train\nimg_2.png;test\nimg_3.png;test\nlost.png;test\n");
    expect_error([&] { load_dataset(tmp.path().string()); },
                 {"scene_split.csv", "lost.png", "does not have"});
    test::write_text(tmp / "scene_split.csv", "filename;split\nimg_0.png;train\nimg_1.png;holdout\n");
    expect_error([&] { load_dataset(tmp.path().string()); }, {"scene_split.csv", "line 3", "'holdout'"});
}

// One SfM point at 1e20 (a failed triangulation) made the initial surfel scale overflow and training stop at
// iteration 1 blaming the learning rates. Such points are dropped at load, and counted.
TEST(DatasetColmap, AbsurdlyFarPointsAreDropped) {
    TempDir tmp;
    ColmapModel m = test::small_model(4, 8, 6);
    const std::size_t points = m.point_xyz.size();
    m.point_xyz.push_back({1e20f, 0, 0});
    m.point_rgb.push_back({1, 1, 1});
    m.point_xyz.push_back({0, -3e7f, 1});
    m.point_rgb.push_back({1, 1, 1});
    test::write_scene(tmp.path(), m);
    const Dataset d = load_dataset(tmp.path().string());
    EXPECT_EQ(d.point_xyz.size(), points);
    EXPECT_EQ(d.point_rgb.size(), points);
    EXPECT_EQ(d.far_points_dropped, 2u);
    EXPECT_GT(d.far_point_limit, 0.0);
    for (const Vec3f& p : d.point_xyz) EXPECT_LT(std::abs(p.x) + std::abs(p.y) + std::abs(p.z), 1e6f);
}

TEST(DatasetColmap, ImagesInSubfolders) {
    TempDir tmp;
    ColmapModel m = test::small_model(2, 8, 6);
    m.images[0].name = "cam_a/0001.jpg";
    m.images[1].name = "cam_b/0001.jpg";
    test::write_scene(tmp.path(), m, false, true);
    test::write_text(tmp / "split.csv", "cam_a/0001.jpg;train\ncam_b/0001.jpg;test\n");
    const Dataset d = load_dataset(tmp.path().string());
    ASSERT_EQ(d.views.size(), 2u);
    EXPECT_EQ(d.views[0].split, Split::Train);
    EXPECT_EQ(d.views[1].split, Split::Test);
    EXPECT_EQ(fs::path(d.views[1].mask_path), tmp.path() / "masks/cam_b/0001.jpg");
    EXPECT_EQ(fs::path(d.views[1].image_path), tmp.path() / "images/cam_b/0001.jpg");
}

TEST(DatasetColmap, MixedImageSizesAndZeroDistortionAreAccepted) {
    TempDir tmp;
    ColmapModel m = test::small_model(3, 16, 12);
    m.cameras[2] = ColmapCamera{2, "SIMPLE_RADIAL", 20, 10, {25, 10, 5, 0}};
    m.cameras[3] = ColmapCamera{3, "OPENCV", 9, 7, {25, 26, 4.5, 3.5, 0, 0, 0, 0}};
    test::write_scene(tmp.path(), m);
    const Dataset d = load_dataset(tmp.path().string(), {.downscale = 2});
    EXPECT_EQ(d.views[0].camera.width, 8);
    EXPECT_EQ(d.views[1].camera.width, 10);
    EXPECT_EQ(d.views[2].camera.width, 4);  // floor(9 / 2)
    EXPECT_EQ(d.views[2].camera.height, 3);
    EXPECT_DOUBLE_EQ(d.views[2].camera.fx, 25.0 * 4 / 9);
    EXPECT_DOUBLE_EQ(d.views[2].camera.cy, 3.5 * 3 / 7);
    const Image small = d.load_image(d.views[2]);
    EXPECT_EQ(small.width, 4);
    EXPECT_EQ(small.height, 3);
}

// --- loader errors, each naming the file ---

TEST(DatasetErrors, MissingImagesFolder) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(2, 8, 6));
    fs::remove_all(tmp.path() / "images");
    expect_error([&] { load_dataset(tmp.path().string()); }, {tmp / "images", "images folder not found"});
}

TEST(DatasetErrors, ImageMissingOnDisk) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(3, 8, 6));
    fs::remove(tmp.path() / "images/img_1.png");
    expect_error([&] { load_dataset(tmp.path().string()); }, {"img_1.png", "images.txt", "missing"});
}

TEST(DatasetErrors, ImageSizeDisagreesWithCamera) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(3, 8, 6));
    write_png(tmp / "images/img_2.png", test::test_image(8, 7, 3));
    expect_error([&] { load_dataset(tmp.path().string()); }, {"img_2.png", "8x7", "camera_id 3", "8x6"});
}

TEST(DatasetErrors, MaskOfTheWrongSize) {
    TempDir tmp;
    test::write_scene(tmp.path(), test::small_model(3, 8, 6), false, true);
    write_png(tmp / "masks/img_1.png", Image(5, 5, 1, 1.0f));
    expect_error([&] { load_dataset(tmp.path().string()); }, {tmp / "masks/img_1.png", "mask is 5x5"});
    // The same check when the mask changes after loading.
    write_png(tmp / "masks/img_1.png", Image(8, 6, 1, 1.0f));
    const Dataset d = load_dataset(tmp.path().string());
    write_png(tmp / "masks/img_1.png", Image(4, 3, 1, 1.0f));
    expect_error([&] { d.load_mask(d.views[1]); }, {tmp / "masks/img_1.png", "4x3"});
    write_png(tmp / "images/img_0.png", Image(4, 3, 3, 1.0f));
    expect_error([&] { d.load_image(d.views[0]); }, {tmp / "images/img_0.png", "4x3"});
}

TEST(DatasetErrors, ImageWithUnknownCamera) {
    TempDir tmp;
    ColmapModel m = test::small_model(2, 8, 6);
    test::write_scene(tmp.path(), m);
    m.images[1].camera_id = 7;
    write_colmap_text(tmp / "sparse/0", m);
    expect_error([&] { load_dataset(tmp.path().string()); }, {"images.txt", "camera_id 7", "img_1.png"});
}

TEST(DatasetErrors, NanInPose) {
    TempDir tmp;
    ColmapModel m = test::small_model(2, 8, 6);
    m.images[0].qvec.y = std::numeric_limits<double>::quiet_NaN();
    test::write_scene(tmp.path(), m, true);
    expect_error([&] { load_dataset(tmp.path().string()); }, {"images.bin", "img_0.png", "NaN"});
}

TEST(DatasetErrors, NotASceneAndBadOptions) {
    TempDir tmp;
    expect_error([&] { load_dataset(tmp.path().string()); }, {tmp.path().string(), "not a scene"});
    expect_error([&] { load_dataset(tmp / "nowhere"); }, {"nowhere", "not found"});
    test::write_scene(tmp.path(), test::small_model(2, 8, 6));
    expect_error([&] { load_dataset(tmp.path().string(), {.downscale = 3}); }, {"downscale"});
}

// --- NeRF-OSR layout ---

void write_matrix(const std::string& path, const std::vector<double>& values) {
    std::string text;
    for (std::size_t i = 0; i < values.size(); ++i)
        text += std::to_string(values[i]) + (i % 4 == 3 ? "\n" : " ");
    test::write_text(path, text);
}

// Camera-to-world: a 30 degree turn about y, centre (1, 2, 3).
std::vector<double> test_c2w() {
    const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
    return {c, 0, s, 1, 0, 1, 0, 2, -s, 0, c, 3, 0, 0, 0, 1};
}

void write_nerfosr_view(const fs::path& split_dir, const std::string& stem, int w, int h, bool mask) {
    for (const char* sub : {"rgb", "mask"}) fs::create_directories(split_dir / sub);
    write_png((split_dir / "rgb" / (stem + ".png")).string(), test::test_image(w, h, 3));
    write_matrix((split_dir / "pose" / (stem + ".txt")).string(), test_c2w());
    write_matrix((split_dir / "intrinsics" / (stem + ".txt")).string(),
                 {50, 0, w / 2.0, 0, 0, 51, h / 2.0, 0, 0, 0, 1, 0, 0, 0, 0, 1});
    if (mask) write_png((split_dir / "mask" / (stem + ".png")).string(), Image(w, h, 1, 1.0f));
}

TEST(DatasetNerfOsr, LayoutPosesAndSplits) {
    TempDir tmp;
    const fs::path final_dir = tmp.path() / "final";
    write_nerfosr_view(final_dir / "train", "01-08_07_30_IMG_6710", 12, 8, true);
    write_nerfosr_view(final_dir / "train", "01-08_07_30_IMG_6711", 10, 8, false);
    write_nerfosr_view(final_dir / "validation", "02-08_07_30_IMG_1", 12, 8, false);
    write_nerfosr_view(final_dir / "test", "29-07_20_30_DSC_2205", 12, 8, false);
    for (const std::string& root : {tmp.path().string(), final_dir.string()}) {
        const Dataset d = load_dataset(root);
        EXPECT_EQ(d.format, "nerf-osr");
        ASSERT_EQ(d.views.size(), 4u);
        EXPECT_EQ(d.split(Split::Train).size(), 2u);
        EXPECT_EQ(d.split(Split::Validation).size(), 1u);
        EXPECT_EQ(d.split(Split::Test).size(), 1u);
        EXPECT_TRUE(d.point_xyz.empty());
        const View& v = view_named(d, "01-08_07_30_IMG_6710.png");
        EXPECT_FALSE(v.mask_path.empty());
        EXPECT_TRUE(view_named(d, "01-08_07_30_IMG_6711.png").mask_path.empty());
        EXPECT_EQ(view_named(d, "01-08_07_30_IMG_6711.png").camera.width, 10);
        EXPECT_EQ(v.camera.fx, 50);
        EXPECT_EQ(v.camera.fy, 51);
        EXPECT_EQ(v.camera.cx, 6);
        EXPECT_EQ(v.camera.cy, 4);
        // c2w maps camera (0, 0, 4) -- 4 units along the optical axis -- to C + 4 * third column.
        const Vec3d centre = v.camera.center();
        EXPECT_NEAR(centre.x, 1, 1e-5);
        EXPECT_NEAR(centre.y, 2, 1e-5);
        EXPECT_NEAR(centre.z, 3, 1e-5);
        const auto m = test_c2w();
        const Vec3d ahead{1 + 4 * m[2], 2 + 4 * m[6], 3 + 4 * m[10]};
        const Vec3d in_camera = v.camera.world_to_camera(ahead);
        EXPECT_NEAR(in_camera.x, 0, 1e-5);
        EXPECT_NEAR(in_camera.y, 0, 1e-5);
        EXPECT_NEAR(in_camera.z, 4, 1e-5);
    }
}

TEST(DatasetNerfOsr, Errors) {
    TempDir tmp;
    const fs::path train = tmp.path() / "final" / "train";
    write_nerfosr_view(train, "a", 12, 8, false);
    fs::remove(train / "pose" / "a.txt");
    expect_error([&] { load_dataset(tmp.path().string()); },
                 {(train / "pose" / "a.txt").string(), "not found"});
    test::write_text((train / "pose" / "a.txt").string(), "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0");
    expect_error([&] { load_dataset(tmp.path().string()); }, {"a.txt", "found 15"});
    write_matrix((train / "pose" / "a.txt").string(), {2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1});
    expect_error([&] { load_dataset(tmp.path().string()); }, {"a.txt", "orthonormal"});
    write_matrix((train / "pose" / "a.txt").string(), {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1});
    expect_error([&] { load_dataset(tmp.path().string()); }, {"a.txt", "reflection"});
    write_matrix((train / "pose" / "a.txt").string(), test_c2w());
    test::write_text((train / "intrinsics" / "a.txt").string(), "50 0 6 0 51 4 0 0 nan");
    expect_error([&] { load_dataset(tmp.path().string()); },
                 {(train / "intrinsics" / "a.txt").string(), "NaN"});
}

TEST(DatasetNerfOsr, PointCloudNextToTheSplits) {
    TempDir tmp;
    const fs::path final_dir = tmp.path() / "final";
    write_nerfosr_view(final_dir / "train", "a", 12, 8, false);
    EXPECT_TRUE(load_dataset(tmp.path().string()).point_xyz.empty());
    EXPECT_EQ(load_dataset(tmp.path().string()).points_path, (final_dir / "points3d.ply").string());
    PlyVertexTable table;
    table.count = 2;
    table.add("x", {1, 4}), table.add("y", {2, 5}), table.add("z", {3, 6});
    write_ply_vertices((final_dir / "points3d.ply").string(), table);
    const Dataset d = load_dataset(tmp.path().string());
    ASSERT_EQ(d.point_xyz.size(), 2u);
    EXPECT_EQ(d.point_xyz[1].y, 5);
    EXPECT_EQ(d.point_rgb[1].x, 0.5f);  // no colours: grey
    table.add("red", {255, 0}), table.add("green", {0, 51}), table.add("blue", {0, 0});
    write_ply_vertices((final_dir / "points3d.ply").string(), table);
    EXPECT_NEAR(load_dataset(tmp.path().string()).point_rgb[1].y, 0.2f, 1e-6f);
    PlyVertexTable empty;
    empty.add("x", {}), empty.add("y", {}), empty.add("z", {});
    write_ply_vertices((final_dir / "points3d.ply").string(), empty);
    expect_error([&] { load_dataset(tmp.path().string()); }, {"points3d.ply", "no points"});
}

}  // namespace
}  // namespace lumigauss
