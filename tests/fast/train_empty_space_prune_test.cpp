// Surfels that paint empty space (train/empty_space_prune.h): the blend-weight sums are the colour a surfel
// alone would give the masked pixels, the decision keeps the surfels that mostly cover the scene, and a
// training run removes a surfel planted in its photos' sky (issue #25: large faint surfels painting a sky
// that the degree-2 environment draws badly survived to the end of training and hung as a veil in front of
// novel views; eval's sky_mean_alpha measured it). The same sweep removes the surfels that add less than a
// few pixels to all the photos together (min_contribution_pixels), at the end of training: a surfel planted
// where no photo looks; and those below the cameras that too few photos see (min_ground_views).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "fast/trainer_test_util.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/train/empty_space_prune.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::random_surfels;
using testing::RandomSceneOptions;

// Channel 0 of a render where only surfel `i` has colour 1: its blend weight in every pixel.
std::vector<float> weights_of(Rasterizer& r, const Camera& cam, SurfelBatch<float> s, std::size_t i) {
    s.channels = 1;
    s.colors.assign(s.size(), 0.0f);
    s.colors[i] = 1.0f;
    RasterImages<float> img;
    r.forward(cam, s, RasterSettings<float>{}, img);
    return img.color;
}

TEST(EmptySpacePrune, WeightsAreEachSurfelsColourOverTheMaskedPixels) {
    const Camera cam = testing::test_camera(64, 48);
    RandomSceneOptions o;
    o.count = 60;
    o.min_scale = 0.1, o.max_scale = 0.6;
    SurfelBatch<float> s = random_surfels<float>(cam, 5, o);
    const std::size_t pixels = std::size_t(cam.width * cam.height);
    std::vector<float> constrained(pixels), empty(pixels);
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            constrained[std::size_t(y * cam.width + x)] = y < 40 ? 1.0f : 0.25f;  // a partly masked photo
            empty[std::size_t(y * cam.width + x)] = x < 20 ? 1.0f : 0.0f;         // its sky on the left
        }
    const auto r = make_rasterizer(RasterBackend::Cpu);
    EmptySpaceWeights w;
    SurfelBatch<float> geometry = s;
    add_empty_space_weights(*r, cam, geometry, constrained, empty, w);
    add_empty_space_weights(*r, cam, geometry, constrained, {}, w);  // a second photo without empty pixels
    ASSERT_EQ(w.constrained.size(), s.size());
    int seen = 0, partly_empty = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const std::vector<float> alone = weights_of(*r, cam, s, i);
        double c = 0, e = 0;
        for (std::size_t p = 0; p < pixels; ++p) c += alone[p] * constrained[p], e += alone[p] * empty[p];
        EXPECT_NEAR(w.constrained[i], 2 * c, 1e-4 * (1 + c)) << "surfel " << i;
        EXPECT_NEAR(w.empty[i], e, 1e-4 * (1 + e)) << "surfel " << i;
        if (std::abs(c - kSeenPixels) > 1e-3) {  // both photos see it alike
            EXPECT_EQ(w.photos_seeing[i], c >= kSeenPixels ? 2u : 0u) << "surfel " << i << ", weight " << c;
        }
        seen += c > 1 ? 1 : 0;
        partly_empty += e > 0.1 && e < c ? 1 : 0;
    }
    EXPECT_GE(seen, 20);  // the scene is not degenerate: surfels are seen, some partly on the empty side
    EXPECT_GE(partly_empty, 3);
}

TEST(EmptySpacePrune, RemovesTheSurfelsMostlyOnEmptyPixels) {
    EmptySpaceWeights w;
    w.constrained = {10, 10, 0, 10, 4};
    w.empty = {6, 4, 0, 5, 4};
    std::size_t removed = 99;
    const std::vector<std::uint8_t> keep = keep_outside_empty_space(w, 0.5, removed);
    EXPECT_EQ(keep, (std::vector<std::uint8_t>{0, 1, 1, 1, 0}));  // unseen kept; exactly half kept
    EXPECT_EQ(removed, 2u);
}

TEST(EmptySpacePrune, RejectsMasksOfAnotherSize) {
    const Camera cam = testing::test_camera(16, 12);
    SurfelBatch<float> s = random_surfels<float>(cam, 1, RandomSceneOptions{});
    const auto r = make_rasterizer(RasterBackend::Cpu);
    EmptySpaceWeights w;
    std::vector<float> wrong(10, 1.0f);
    EXPECT_THROW(add_empty_space_weights(*r, cam, s, wrong, {}, w), Error);
}

// A large opaque surfel standing in the sky of the first training photo, `distance` in front of it, facing
// it.
std::vector<float> painter_row(const TrainView& view, ModelParam p, double distance) {
    const Camera& cam = view.camera;
    // The sky pixel nearest the top centre.
    int px = cam.width / 2, py = 0;
    for (int y = 0; y < cam.height; ++y)
        if (view.sky.at(px, y, 0) > 0.5f) {
            py = y + 2;
            break;
        }
    const Vec3d dir_cam = normalize(Vec3d{(px + 0.5 - cam.cx) / cam.fx, (py + 0.5 - cam.cy) / cam.fy, 1.0});
    const Mat3d to_world = transpose(cam.rotation);
    const Vec3d pos = cam.center() + to_world * dir_cam * distance;
    const double scale = 6 * distance / cam.fx;  // about 12 pixels across
    switch (p) {
        case ModelParam::Xyz:
            return {float(pos.x), float(pos.y), float(pos.z)};
        case ModelParam::Rotation: {
            // w x y z (quaternion_from_rotation's order); its normal is the camera's axis.
            const Vec4<double> q = quaternion_from_rotation(to_world);
            return {float(q[0]), float(q[1]), float(q[2]), float(q[3])};
        }
        case ModelParam::Scaling:
            return {float(std::log(scale)), float(std::log(scale))};
        case ModelParam::Opacity:
            return {inverse_sigmoid(0.9f)};
        default:
            return std::vector<float>(std::size_t(SurfelModel::width(p)), 0.1f);
    }
}

using PlantedRow = std::function<std::vector<float>(const Trainer&, ModelParam)>;

// Plants one surfel (`row` gives its parameters) into the starting surfels, runs iteration `iteration` (by
// default one of a sweep: after densification, a multiple of the opacity-reset rhythm, in the shadowed
// stage), and returns the planted surfel's index afterwards, or -1 when the step removed it.
std::size_t planted_after_a_sweep(const TrainConfig& c, const PlantedRow& row, bool expect_sweep,
                                  std::int64_t iteration = 0) {
    Trainer t = trainer_test::make_trainer(c);
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (ModelParam p : kAllModelParams) {
        raw[int(p)] = t.state().model.param(p);
        const std::vector<float> planted = row(t, p);
        raw[int(p)].insert(raw[int(p)].end(), planted.begin(), planted.end());
    }
    const std::vector<float>& xyz = raw[int(ModelParam::Xyz)];
    const Vec3f planted{xyz[xyz.size() - 3], xyz[xyz.size() - 2], xyz[xyz.size() - 1]};
    t.state().model =
        GaussianModel::from_raw(std::move(raw), t.state().scene_extent, model_learning_rates(c));
    t.state().iteration = (iteration > 0 ? iteration : 2 * c.opacity_reset_interval) - 1;
    const StepReport r = t.step();
    EXPECT_EQ(r.empty_space_swept, expect_sweep);
    // The step moved it a little (without the prune, Adam steps the positions).
    const auto& p = t.state().model.param(ModelParam::Xyz);
    const double near = 0.01 * t.state().scene_extent;
    for (std::size_t i = 0; i < t.state().model.size(); ++i)
        if (length(Vec3f{p[3 * i], p[3 * i + 1], p[3 * i + 2]} - planted) < near) return i;
    return std::size_t(-1);
}

std::size_t painter_after_a_sweep(double share) {
    TrainConfig c = trainer_test::shrunk_config();
    c.empty_space_prune_share = share;
    c.prune_until_end = false;
    const PlantedRow painter = [](const Trainer& t, ModelParam p) {
        return painter_row(t.views().front(), p, 0.5 * t.state().scene_extent);
    };
    return planted_after_a_sweep(c, painter, share > 0);
}

TEST(EmptySpacePrune, TrainingRemovesASurfelPlantedInTheSky) {
    const TrainConfig c = trainer_test::shrunk_config();
    ASSERT_GE(2 * c.opacity_reset_interval, c.densify_until);
    ASSERT_GT(2 * c.opacity_reset_interval, c.start_shadowed);
    ASSERT_FALSE(trainer_test::tiny_scene().views.front().sky.empty());
    EXPECT_NE(painter_after_a_sweep(0.0), std::size_t(-1)) << "without the prune the painter stays";
    EXPECT_EQ(painter_after_a_sweep(0.5), std::size_t(-1)) << "the painter survived the sweep";
}

TEST(EmptySpacePrune, LowContributionRemovesTheSurfelsBelowThePixelCount) {
    EmptySpaceWeights w;
    w.constrained = {10, 3.9, 0, 4, 1};
    w.empty = {0, 0, 0, 0, 0};
    std::vector<std::uint8_t> keep = {1, 1, 1, 1, 0};  // the last already removed as a painter
    EXPECT_EQ(remove_low_contribution(w, 4.0, keep), 2u);
    EXPECT_EQ(keep, (std::vector<std::uint8_t>{1, 0, 0, 1, 0}));
    std::vector<std::uint8_t> short_flags(2, 1);
    EXPECT_THROW(remove_low_contribution(w, 4.0, short_flags), Error);
}

TEST(EmptySpacePrune, WeaklySeenGroundRemovesTheLowSurfelsFewPhotosSee) {
    EmptySpaceWeights w;
    w.reset(5);
    w.photos_seeing = {0, 2, 3, 1, 0};
    // Up is +y here; the cameras' feet at height 1.5.
    const std::vector<float> centres = {0, 1, 0, 5, -2, 5, 0, 0, 0, 0, 2, 0, 9, 1.4f, 9};
    std::vector<std::uint8_t> keep = {1, 1, 1, 1, 0};  // the last already removed
    EXPECT_EQ(remove_weakly_seen_ground(w, centres, Vec3f{0, 1, 0}, 1.5, 3, keep), 2u);
    // Low and seen by 0 or 2 photos: removed; seen by 3: kept; above the cameras: kept.
    EXPECT_EQ(keep, (std::vector<std::uint8_t>{0, 0, 1, 1, 0}));
    std::vector<std::uint8_t> short_flags(2, 1);
    EXPECT_THROW(remove_weakly_seen_ground(w, centres, Vec3f{0, 1, 0}, 1.5, 3, short_flags), Error);
    std::vector<std::uint8_t> all(5, 1);
    EXPECT_EQ(remove_weakly_seen_ground(w, centres, Vec3f{0, 1, 0}, 1.5, 0, all), 0u) << "0 photos: none";
}

Vec3d mean_camera_centre(const Trainer& t) {
    Vec3d centre{0, 0, 0};
    for (const TrainView& v : t.views())
        centre = centre + v.camera.center() * (1.0 / double(t.views().size()));
    return centre;
}

// Whether x projects anywhere near a training photo's frame.
bool seen_by_any(const Trainer& t, Vec3d x) {
    for (const TrainView& v : t.views()) {
        const Vec3d c = v.camera.world_to_camera(x);
        if (c.z <= 0) continue;
        const double u = v.camera.fx * c.x / c.z + v.camera.cx, w = v.camera.fy * c.y / c.z + v.camera.cy;
        if (u > -v.camera.width && u < 2.0 * v.camera.width && w > -v.camera.height &&
            w < 2.0 * v.camera.height)
            return true;
    }
    return false;
}

// A small opaque surfel at `pos`, facing +z.
std::vector<float> small_surfel_row(const Trainer& t, ModelParam p, Vec3d pos) {
    const double extent = t.state().scene_extent;
    switch (p) {
        case ModelParam::Xyz:
            return {float(pos.x), float(pos.y), float(pos.z)};
        case ModelParam::Rotation:
            return {1, 0, 0, 0};
        case ModelParam::Scaling:
            return {float(std::log(0.01 * extent)), float(std::log(0.01 * extent))};
        case ModelParam::Opacity:
            return {inverse_sigmoid(0.9f)};
        default:
            return std::vector<float>(std::size_t(SurfelModel::width(p)), 0.1f);
    }
}

// A small opaque surfel far from the scene, where no training photo looks.
std::vector<float> unseen_row(const Trainer& t, ModelParam p) {
    const double extent = t.state().scene_extent;
    const Vec3d centre = mean_camera_centre(t);
    Vec3d pos = centre;
    for (const Vec3d dir :
         {Vec3d{0, 0, -1}, Vec3d{0, 0, 1}, Vec3d{1, 0, 0}, Vec3d{-1, 0, 0}, Vec3d{0, 1, 0}, Vec3d{0, -1, 0}})
        if (!seen_by_any(t, centre + dir * (20 * extent))) {
            pos = centre + dir * (20 * extent);
            break;
        }
    return small_surfel_row(t, p, pos);
}

TEST(EmptySpacePrune, TrainingRemovesASurfelNoPhotoSees) {
    TrainConfig c = trainer_test::shrunk_config();
    c.prune_until_end = false;
    {  // the planted surfel is out of every photo (else the test proves nothing)
        Trainer t = trainer_test::make_trainer(c);
        const std::vector<float> xyz = unseen_row(t, ModelParam::Xyz);
        Vec3d centre{0, 0, 0};
        for (const TrainView& v : t.views())
            centre = centre + v.camera.center() * (1.0 / double(t.views().size()));
        ASSERT_GT(length(Vec3d{xyz[0], xyz[1], xyz[2]} - centre), 10 * t.state().scene_extent);
    }
    // The rule runs on the finished model: at the last iteration.
    c.min_contribution_pixels = 0;
    EXPECT_NE(planted_after_a_sweep(c, unseen_row, false, c.iterations), std::size_t(-1)) << "no rule, kept";
    c.min_contribution_pixels = 4;
    EXPECT_EQ(planted_after_a_sweep(c, unseen_row, true, c.iterations), std::size_t(-1)) << "it survived";
    // Not at the sweeps before (it might still be moved into view).
    c.empty_space_prune_share = 0.5;
    EXPECT_NE(planted_after_a_sweep(c, unseen_row, true), std::size_t(-1)) << "removed before the end";
}

// A surfel no photo sees, 20 scene extents below (sign -1) or above (+1) the cameras' mean centre.
std::vector<float> unseen_row_along_up(const Trainer& t, ModelParam p, double sign) {
    const Vec3d up = t.sky_horizon().up.cast<double>();
    return small_surfel_row(t, p, mean_camera_centre(t) + up * (sign * 20 * t.state().scene_extent));
}

TEST(EmptySpacePrune, TrainingRemovesTheUnseenSurfelsBelowTheCameras) {
    TrainConfig c = trainer_test::shrunk_config();
    c.prune_until_end = false;
    {  // neither planted surfel is in a photo (else the test proves nothing)
        Trainer t = trainer_test::make_trainer(c);
        for (double sign : {-1.0, 1.0}) {
            const std::vector<float> xyz = unseen_row_along_up(t, ModelParam::Xyz, sign);
            ASSERT_FALSE(seen_by_any(t, Vec3d{xyz[0], xyz[1], xyz[2]}));
        }
    }
    const PlantedRow below = [](const Trainer& t, ModelParam p) { return unseen_row_along_up(t, p, -1); };
    const PlantedRow above = [](const Trainer& t, ModelParam p) { return unseen_row_along_up(t, p, 1); };
    // On the finished model (the last iteration); the one above the cameras stays.
    c.min_ground_views = 0;
    EXPECT_NE(planted_after_a_sweep(c, below, c.min_contribution_pixels > 0, c.iterations), std::size_t(-1))
        << "no rule, kept";
    c.min_ground_views = 3;
    EXPECT_EQ(planted_after_a_sweep(c, below, true, c.iterations), std::size_t(-1)) << "it survived";
    EXPECT_NE(planted_after_a_sweep(c, above, true, c.iterations), std::size_t(-1)) << "removed above";
    // Not before (right after densification, the surfels left grew back into the same ground).
    c.empty_space_prune_share = 0.5;
    EXPECT_NE(planted_after_a_sweep(c, below, true), std::size_t(-1)) << "removed before the end";
}

}  // namespace
}  // namespace lumigauss
