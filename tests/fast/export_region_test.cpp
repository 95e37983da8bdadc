// export/export_region.h: `export --crop-radius`, `--crop-box` and `--recentre` keep the surfels whose
// centres are inside, every parameter row with them, and move positions and cameras alike.
#include <gtest/gtest.h>

#include <gmock/gmock.h>

#include "export_test_scene.h"
#include "lumigauss/export/export_region.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using ::testing::HasSubstr;

// Seven surfels of the cube model moved to x = 0, 1, 2, 3, 4, 100, 101 (y = z = 0): the median centre is
// x = 3, and every parameter row keeps a recognisable opacity (the row index / 10).
SurfelModel line_model() {
    GaussianModel cube = export_test::cube_model(5, 7);
    std::vector<std::vector<float>> raw;
    for (const ModelParam p : kAllModelParams) raw.push_back(cube.param(p));
    const float xs[] = {0, 1, 2, 3, 4, 100, 101};
    for (std::size_t i = 0; i < 7; ++i) {
        raw[int(ModelParam::Xyz)][3 * i] = xs[i];
        raw[int(ModelParam::Xyz)][3 * i + 1] = 0;
        raw[int(ModelParam::Xyz)][3 * i + 2] = 0;
        raw[int(ModelParam::Opacity)][i] = float(i) / 10;
    }
    return SurfelModel::from_raw(std::move(raw));
}

std::vector<float> xs_of(const SurfelModel& m) {
    std::vector<float> xs;
    for (std::size_t i = 0; i < m.size(); ++i) xs.push_back(m.param(ModelParam::Xyz)[3 * i]);
    return xs;
}

TEST(ExportRegion, RadiusAboutTheMedianCentreKeepsEveryRowOfTheSurfelsInside) {
    const SurfelModel model = line_model();
    ExportRegion region;
    region.radius = 1.5;
    const RegionedModel out = apply_export_region(model, {}, region);
    EXPECT_EQ(out.centre.x, 3.0);
    EXPECT_EQ(out.removed, 4u);
    EXPECT_EQ(xs_of(out.model), (std::vector<float>{2, 3, 4}));
    EXPECT_EQ(out.model.param(ModelParam::Opacity), (std::vector<float>{0.2f, 0.3f, 0.4f}));
    for (const ModelParam p : kAllModelParams)
        EXPECT_EQ(out.model.param(p).size(), 3u * std::size_t(SurfelModel::width(p))) << int(p);
    EXPECT_EQ(out.translation.x, 0.0);  // not recentred
}

TEST(ExportRegion, BoxCentreIsTheOriginWhenRecentred) {
    const SurfelModel model = line_model();
    ExportRegion region;
    region.box = parse_crop_box("-0.5, -1, -1, 2.5, 1, 1", "--crop-box");
    region.recentre = true;
    const std::vector<Vec3d> cameras = {{1, 2, 3}, {-4, 0, 0}};
    const RegionedModel out = apply_export_region(model, cameras, region);
    EXPECT_EQ(out.centre.x, 1.0);
    EXPECT_EQ(xs_of(out.model), (std::vector<float>{-1, 0, 1}));
    ASSERT_EQ(out.cameras.size(), 2u);
    EXPECT_EQ(out.cameras[0].x, 0.0);
    EXPECT_EQ(out.cameras[0].y, 2.0);
    EXPECT_EQ(out.cameras[1].x, -5.0);
    // Recentring alone keeps everything and moves the median centre (x = 3) to the origin.
    ExportRegion only;
    only.recentre = true;
    const RegionedModel moved = apply_export_region(model, cameras, only);
    EXPECT_EQ(moved.removed, 0u);
    EXPECT_EQ(xs_of(moved.model), (std::vector<float>{-3, -2, -1, 0, 1, 97, 98}));
}

TEST(ExportRegion, BadRegionsAreRefused) {
    const SurfelModel model = line_model();
    ExportRegion zero;
    zero.radius = 0.0;
    EXPECT_THROW(apply_export_region(model, {}, zero), Error);
    ExportRegion far;
    far.box = parse_crop_box("50,50,50,60,60,60", "--crop-box");
    try {
        apply_export_region(model, {}, far);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr("keeps none of the 7 surfels"));
    }
    for (const char* bad : {"1,2,3,4,5", "1,2,3,4,5,6,7", "a,2,3,4,5,6", "1,2,3,0,5,6", "1,2,3,4,5,nan", ""})
        try {
            parse_crop_box(bad, "--crop-box");
            FAIL() << "accepted '" << bad << "'";
        } catch (const Error& e) {
            EXPECT_THAT(e.what(), HasSubstr("--crop-box")) << bad;
        }
}

}  // namespace
}  // namespace lumigauss
