// COLMAP lens models and undistortion on load: known answers of the model equations, a photo made through a
// lens (inverted here by Newton's method, independently of the code) that undistorts back to the pinhole
// picture, the pixels a lens leaves uncovered, and scenes whose cameras have distortion.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "fast/io_test_util.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/lens_distortion.h"

namespace lumigauss {
namespace {

using test::expect_error;
using test::TempDir;

LensDistortion lens_of(const std::string& model, const std::vector<double>& params) {
    LensDistortion lens;
    EXPECT_TRUE(colmap_lens_distortion(model, params, lens)) << model;
    return lens;
}

TEST(LensDistortion, KnownAnswersOfColmapModels) {
    const double u = 0.3, v = -0.2, r2 = u * u + v * v;
    // SIMPLE_RADIAL f cx cy k
    Vec2<double> q = lens_of("SIMPLE_RADIAL", {500, 320, 240, 0.1}).distort({u, v});
    EXPECT_NEAR(q.x, u * (1 + 0.1 * r2), 1e-15);
    EXPECT_NEAR(q.y, v * (1 + 0.1 * r2), 1e-15);
    // RADIAL f cx cy k1 k2
    q = lens_of("RADIAL", {500, 320, 240, 0.1, -0.05}).distort({u, v});
    EXPECT_NEAR(q.x, u * (1 + 0.1 * r2 - 0.05 * r2 * r2), 1e-15);
    // OPENCV fx fy cx cy k1 k2 p1 p2
    q = lens_of("OPENCV", {500, 510, 320, 240, 0.1, -0.05, 0.01, -0.02}).distort({u, v});
    const double radial = 1 + 0.1 * r2 - 0.05 * r2 * r2;
    EXPECT_NEAR(q.x, u * radial + 2 * 0.01 * u * v + -0.02 * (r2 + 2 * u * u), 1e-15);
    EXPECT_NEAR(q.y, v * radial + 2 * -0.02 * u * v + 0.01 * (r2 + 2 * v * v), 1e-15);
    // FULL_OPENCV fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6
    q = lens_of("FULL_OPENCV", {500, 510, 320, 240, 0.1, -0.05, 0.01, -0.02, 0.003, 0.2, 0.01, 0.001})
            .distort({u, v});
    const double rational = (1 + 0.1 * r2 - 0.05 * r2 * r2 + 0.003 * r2 * r2 * r2) /
                            (1 + 0.2 * r2 + 0.01 * r2 * r2 + 0.001 * r2 * r2 * r2);
    EXPECT_NEAR(q.x, u * rational + 2 * 0.01 * u * v + -0.02 * (r2 + 2 * u * u), 1e-15);
    EXPECT_NEAR(q.y, v * rational + 2 * -0.02 * u * v + 0.01 * (r2 + 2 * v * v), 1e-15);

    EXPECT_TRUE(lens_of("PINHOLE", {500, 510, 320, 240}).is_identity());
    EXPECT_TRUE(lens_of("SIMPLE_RADIAL", {500, 320, 240, 0}).is_identity());
    LensDistortion unused;
    EXPECT_FALSE(colmap_lens_distortion("THIN_PRISM_FISHEYE", std::vector<double>(12, 0.0), unused));
}

// COLMAP's fisheyes (models.h, FisheyeCameraModel): theta = atan(r), theta_d = theta (1 + k1 theta^2 + ...),
// the point scaled by theta_d / r.
TEST(LensDistortion, KnownAnswersOfColmapFisheyeModels) {
    const double u = 0.3, v = -0.2, r = std::hypot(u, v), t = std::atan(r), t2 = t * t;
    // OPENCV_FISHEYE fx fy cx cy k1 k2 k3 k4
    Vec2<double> q = lens_of("OPENCV_FISHEYE", {500, 510, 320, 240, 0.1, -0.05, 0.01, 0.002}).distort({u, v});
    const double td = t * (1 + 0.1 * t2 - 0.05 * t2 * t2 + 0.01 * t2 * t2 * t2 + 0.002 * t2 * t2 * t2 * t2);
    EXPECT_NEAR(q.x, u * td / r, 1e-15);
    EXPECT_NEAR(q.y, v * td / r, 1e-15);
    // SIMPLE_RADIAL_FISHEYE f cx cy k; RADIAL_FISHEYE f cx cy k1 k2
    q = lens_of("SIMPLE_RADIAL_FISHEYE", {500, 320, 240, 0.1}).distort({u, v});
    EXPECT_NEAR(q.x, u * t * (1 + 0.1 * t2) / r, 1e-15);
    q = lens_of("RADIAL_FISHEYE", {500, 320, 240, 0.1, -0.05}).distort({u, v});
    EXPECT_NEAR(q.y, v * t * (1 + 0.1 * t2 - 0.05 * t2 * t2) / r, 1e-15);
    // An equidistant lens without terms still bends rays: it is no pinhole. Its centre stays.
    const LensDistortion plain = lens_of("OPENCV_FISHEYE", {500, 510, 320, 240, 0, 0, 0, 0});
    EXPECT_FALSE(plain.is_identity());
    EXPECT_NEAR(plain.distort({u, v}).x, u * t / r, 1e-15);
    EXPECT_EQ(plain.distort({0, 0}).x, 0.0);
}

// A smooth picture of the world as the ideal pinhole sees it, by normalized coordinates.
double world_picture(Vec2<double> p, int channel) {
    return 0.5 + 0.4 * std::sin(3.0 * p.x + 1.3 * channel) * std::cos(2.0 * p.y - 0.7 * channel);
}

// The photo the lens takes: each photo pixel shows the pinhole ray the lens bent onto it, found by Newton's
// method on the model equations (numerical Jacobian), written here independently of lens_distortion.cpp.
Image photo_through_lens(const Camera& c, const LensDistortion& lens) {
    Image photo(c.width, c.height, 3);
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
            const Vec2<double> target{(x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy};
            Vec2<double> p = target;
            for (int it = 0; it < 50; ++it) {
                const Vec2<double> f = lens.distort(p) - target;
                const double h = 1e-7;
                const Vec2<double> du = (1 / h) * (lens.distort({p.x + h, p.y}) - lens.distort(p));
                const Vec2<double> dv = (1 / h) * (lens.distort({p.x, p.y + h}) - lens.distort(p));
                const double det = du.x * dv.y - du.y * dv.x;
                p.x -= (dv.y * f.x - dv.x * f.y) / det;
                p.y -= (-du.y * f.x + du.x * f.y) / det;
            }
            for (int k = 0; k < 3; ++k) photo.at(x, y, k) = float(world_picture(p, k));
        }
    return photo;
}

Camera test_camera() {
    Camera c;
    c.width = 96, c.height = 72, c.fx = 80, c.fy = 82, c.cx = 47.0, c.cy = 37.5;
    return c;
}

// Largest error against the pinhole picture, over the covered pixels (counted), of the photo taken through
// `lens` and undistorted as if taken through `assumed`.
double undistortion_error(const Camera& c, const LensDistortion& lens, int& covered,
                          std::optional<LensDistortion> assumed = std::nullopt) {
    const Image undistorted = undistort_image(photo_through_lens(c, lens), c, assumed.value_or(lens));
    const Image valid = undistort_validity(c, lens);
    double worst = 0;
    covered = 0;
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
            if (valid.at(x, y, 0) == 0) {
                for (int k = 0; k < 3; ++k) EXPECT_EQ(undistorted.at(x, y, k), 0.0f);
                continue;
            }
            ++covered;
            const Vec2<double> p{(x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy};
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::abs(undistorted.at(x, y, k) - world_picture(p, k)));
        }
    return worst;
}

TEST(LensDistortion, UndistortingAPhotoGivesThePinholePicture) {
    const Camera c = test_camera();
    int covered = 0;
    // Barrel distortion (every pinhole ray of the image is in the photo) and an OPENCV lens with tangential
    // terms. The bilinear resampling of this smooth picture errs by well under 1 %; doing nothing errs by 10
    // %.
    const LensDistortion barrel = lens_of("SIMPLE_RADIAL", {80, 47.0, 37.5, -0.08});
    EXPECT_LT(undistortion_error(c, barrel, covered), 0.01);
    EXPECT_EQ(covered, c.width * c.height);
    const LensDistortion opencv = lens_of("OPENCV", {80, 82, 47.0, 37.5, -0.1, 0.02, 0.004, -0.003});
    EXPECT_LT(undistortion_error(c, opencv, covered), 0.01);
    EXPECT_GT(undistortion_error(c, opencv, covered, LensDistortion{}), 0.03)
        << "the comparison must see the lens";
}

// A fisheye photo undistorted onto the pinhole of the same focal length: every pinhole ray is in the photo
// (the fisheye sees wider) and the picture comes back.
TEST(LensDistortion, AFisheyePhotoUndistortsToThePinholePicture) {
    const Camera c = test_camera();
    const LensDistortion fisheye = lens_of("OPENCV_FISHEYE", {80, 82, 47.0, 37.5, 0.05, -0.01, 0.002, 0.0});
    int covered = 0;
    EXPECT_LT(undistortion_error(c, fisheye, covered), 0.01);
    EXPECT_EQ(covered, c.width * c.height);
    EXPECT_GT(undistortion_error(c, fisheye, covered, LensDistortion{}), 0.03)
        << "the comparison must see the lens";
}

TEST(LensDistortion, PincushionLeavesTheCornersUncovered) {
    const Camera c = test_camera();
    const LensDistortion pincushion = lens_of("RADIAL", {80, 47.0, 37.5, 0.15, 0.02});
    int covered = 0;
    EXPECT_LT(undistortion_error(c, pincushion, covered), 0.01);
    const Image valid = undistort_validity(c, pincushion);
    EXPECT_EQ(valid.at(0, 0, 0), 0.0f);
    EXPECT_EQ(valid.at(c.width - 1, c.height - 1, 0), 0.0f);
    EXPECT_EQ(valid.at(47, 37, 0), 1.0f);
    EXPECT_LT(covered, c.width * c.height);
    EXPECT_GT(covered, c.width * c.height / 2);
}

TEST(LensDistortion, RaysPastTheFoldOfTheLensAreUncovered) {
    // r (1 + k r^2) stops growing at r = 1 / sqrt(-3 k) = 0.577 for k = -1: the corners (r = 0.75) are past
    // it and land on pixels that nearer rays already hold; the centre is not.
    const Camera c = test_camera();
    const LensDistortion folded = lens_of("SIMPLE_RADIAL", {80, 47.0, 37.5, -1.0});
    const Image valid = undistort_validity(c, folded);
    EXPECT_EQ(valid.at(0, 0, 0), 0.0f);
    EXPECT_EQ(valid.at(47, 37, 0), 1.0f);
    for (int x = 0; x < c.width; ++x) {  // the middle row: covered exactly up to the fold radius
        const double r = std::abs((x + 0.5 - c.cx) / c.fx);
        if (std::abs(r - 1 / std::sqrt(3.0)) > 0.01) {
            EXPECT_EQ(valid.at(x, 37, 0), r < 1 / std::sqrt(3.0) ? 1 : 0) << x;
        }
    }
}

// A COLMAP scene of one OPENCV camera whose photo was taken through the lens: the dataset undistorts the
// photo and its mask, and masks out what the photo does not cover.
TEST(DatasetColmap, DistortedCamerasAreUndistortedOnLoad) {
    TempDir tmp;
    const Camera c = test_camera();
    ColmapModel m = test::small_model(2, c.width, c.height);
    const std::vector<double> params{c.fx, c.fy, c.cx, c.cy, 0.12, 0.02, 0.004, -0.003};
    m.cameras[2] = ColmapCamera{2, "OPENCV", c.width, c.height, params};
    test::write_scene(tmp.path(), m, false, true);
    const LensDistortion lens = lens_of("OPENCV", params);
    const Image photo = photo_through_lens(c, lens);
    // Float pixels (the readers sniff the format from the content): no 8-bit rounding in the comparison.
    write_exr(tmp / "images/img_1.png", photo);
    write_png(tmp / "masks/img_1.png", Image(c.width, c.height, 1, 1.0f));

    const Dataset d = load_dataset(tmp.path().string());
    EXPECT_EQ(d.undistorted_views(), 1u);
    EXPECT_TRUE(d.views[0].lens.is_identity());
    EXPECT_TRUE(d.load_coverage(d.views[0]).empty());
    const View& v = d.views[1];
    EXPECT_EQ(v.camera.fx, c.fx);  // the pinhole keeps COLMAP's intrinsics
    EXPECT_EQ(v.camera.cy, c.cy);
    const Image image = d.load_image(v), mask = d.load_mask(v), coverage = d.load_coverage(v);
    const Image valid = undistort_validity(c, lens);
    EXPECT_EQ(coverage.pixels, valid.pixels);
    EXPECT_EQ(mask.pixels, valid.pixels) << "an all-ones mask file keeps only the covered pixels";
    EXPECT_LT(valid.at(0, 0, 0), 1.0f);
    double worst = 0;
    for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x)
            if (valid.at(x, y, 0) > 0)
                worst = std::max(
                    worst, std::abs(image.at(x, y, 1) -
                                    world_picture({(x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy}, 1)));
    EXPECT_LT(worst, 0.01);

    // Downscaled: undistorted at the photo's size, then averaged, like an undistorted photo would be.
    const Dataset half = load_dataset(tmp.path().string(), {.downscale = 2});
    const View& hv = half.views[1];
    const Image small = half.load_image(hv), small_mask = half.load_mask(hv);
    EXPECT_EQ(small.width, c.width / 2);
    EXPECT_EQ(small_mask.pixels, resize_area(valid, c.width / 2, c.height / 2).pixels);
    EXPECT_EQ(small.pixels, resize_area(undistort_image(photo, c, lens), c.width / 2, c.height / 2).pixels);
}

TEST(DatasetColmap, AnUnhandledLensIsRefusedWithTheFix) {
    TempDir tmp;
    ColmapModel m = test::small_model(2, 8, 6);
    m.cameras[2] = ColmapCamera{2, "THIN_PRISM_FISHEYE", 8, 6, {25, 25, 4, 3, 0.1, 0, 0, 0, 0, 0, 0, 0}};
    test::write_scene(tmp.path(), m);
    expect_error([&] { load_dataset(tmp.path().string()); },
                 {"cameras.txt", "camera_id 2", "THIN_PRISM_FISHEYE", "colmap image_undistorter", "masks/"});
}

// The one-focal fisheye models take f, cx, cy as the pinhole's intrinsics.
TEST(DatasetColmap, FisheyeCamerasLoadWithTheirIntrinsics) {
    TempDir tmp;
    ColmapModel m = test::small_model(2, 8, 6);
    m.cameras[2] = ColmapCamera{2, "SIMPLE_RADIAL_FISHEYE", 8, 6, {25, 4.5, 3.25, 0.1}};
    test::write_scene(tmp.path(), m);
    const Dataset d = load_dataset(tmp.path().string());
    const View& v = d.views[1];
    EXPECT_EQ(v.camera.fx, 25.0);
    EXPECT_EQ(v.camera.fy, 25.0);
    EXPECT_EQ(v.camera.cx, 4.5);
    EXPECT_EQ(v.camera.cy, 3.25);
    EXPECT_TRUE(v.lens.fisheye);
    EXPECT_EQ(v.lens.k1, 0.1);
    EXPECT_EQ(d.undistorted_views(), 1u);
}

}  // namespace
}  // namespace lumigauss
