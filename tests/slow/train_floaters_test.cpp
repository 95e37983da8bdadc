// Regression tests of issue #25 on the tiny synthetic plaza: the two mechanisms that spoiled novel views,
// each shown with the paper's behaviour and fixed by the default presets. Slow tier (trainings of a few
// hundred iterations): run in the release tree by scripts/test.sh (and CI).
//   1. Curtains at the cameras: randomly turned initial surfels of the sparse ground points next to a camera
//      stand up across its view above the horizon, where only that camera sees them large.
//   2. The sky painted with surfels: with a black background every sky pixel must be produced by a surfel,
//      which hangs in front of the building from another viewpoint.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fast/synth_test_util.h"
#include "fast/trainer_test_util.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/synth/synth.h"
#include "lumigauss/train/trainer.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;

using trainer_test::tiny_scene;
using trainer_test::TinyScene;

// Surfels within `near` of the camera whose reachable pixels reach more than a tenth of the image height
// above the camera's horizon (the image row of the world's horizontal directions, +z up).
int curtains(const GaussianModel& model, const Camera& camera, double near) {
    SurfelBatch<float> batch;
    model.activated(batch);
    batch.channels = 1;
    batch.colors.assign(batch.size(), 0.5f);
    RasterState<float> state;
    rasterize_forward_cpu(camera, batch, RasterSettings<float>{}, state);
    Vec3d forward = transpose(camera.rotation).col(2);
    forward.z = 0;
    const Vec3d c = camera.rotation * forward;
    const double horizon = camera.fy * c.y / c.z + camera.cy;
    const int top_rows = int(horizon - 0.1 * camera.height);
    int count = 0;
    for (std::size_t i = 0; i < batch.size(); ++i) {
        if (!state.visible[i] || state.footprints[i].depth > near) continue;
        bool above = false;
        for (int y = 0; y < top_rows && !above; ++y)
            for (int x = 0; x < camera.width && !above; ++x) {
                raster::SplatSample<float> sample;
                above = raster::evaluate_splat(state.splats[i], float(x) + 0.5f, float(y) + 0.5f, sample);
            }
        count += above ? 1 : 0;
    }
    return count;
}

// Sparse SfM points of a ground plane around a camera at eye height, as in a tourist photo collection: the
// surfels they start as, randomly turned (officially) or in the plane of their neighbours.
TEST(TrainFloaters, InitialSurfelsNearTheCameraLieInTheGround) {
    std::mt19937 rng(11);
    std::normal_distribution<float> noise(0.0f, 0.05f);
    std::vector<Vec3f> xyz, rgb;
    for (int i = -20; i <= 20; ++i)
        for (int j = -20; j <= 20; ++j)
            xyz.push_back({float(i) + noise(rng), float(j) + noise(rng), noise(rng)}),
                rgb.push_back({0.5f, 0.5f, 0.5f});
    Camera camera;
    camera.width = 160, camera.height = 120, camera.fx = camera.fy = 140, camera.cx = 80, camera.cy = 60;
    camera.rotation = Mat3d{{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}};      // looking along +y, image y = world -z
    camera.translation = -(camera.rotation * Vec3d{0.3, -0.2, 1.6});  // at eye height
    const int random = curtains(GaussianModel::from_points(xyz, rgb, 10.0, 0, {}, false), camera, 3.0);
    const int oriented = curtains(GaussianModel::from_points(xyz, rgb, 10.0, 0, {}, true), camera, 3.0);
    std::printf(
        "[ measured ] ground surfels < 3 m from the camera reaching above its horizon: random %d, "
        "from the points %d\n",
        random, oriented);
    EXPECT_GE(random, 3) << "the scene no longer reproduces the curtains";
    EXPECT_EQ(oriented, 0);
    // And the presets: the paper keeps the official random turn, the default ones start from the points.
    EXPECT_FALSE(train_preset("paper").init_normals_from_points);
    EXPECT_TRUE(train_preset("default").init_normals_from_points);
    EXPECT_TRUE(train_preset("fast").init_normals_from_points);
}

// Share of the test views' sky pixels (gt/mask = 0) where the trained model's alpha exceeds 0.5.
double sky_coverage(const TinyScene& s, const GaussianModel& model) {
    std::size_t sky = 0, covered = 0;
    for (const View* v : s.data.split(Split::Test)) {
        std::filesystem::path mask_path = std::filesystem::path(s.root) / "gt" / "mask" / v->name;
        const Image mask = read_image(mask_path.replace_extension(".png").string());
        const RasterImages<float> img =
            render_with_environment(model, v->camera, ShCoeffs<float>{}, ShadingMode::Unshadowed);
        for (std::size_t p = 0; p < img.alpha.size(); ++p) {
            if (mask.pixels[p * std::size_t(mask.channels)] != 0.0f) continue;
            ++sky;
            covered += img.alpha[p] > 0.5f ? 1 : 0;
        }
    }
    return sky > 0 ? double(covered) / double(sky) : 0.0;
}

TEST(TrainFloaters, TheSkyIsDrawnBehindTheSurfelsNotByThem) {
    const TinyScene& s = tiny_scene();
    const auto train = [&](const char* preset) {
        TrainConfig c = train_preset(preset);
        c.iterations = 400;  // stage 1 only: the sky question is settled there
        c.warmup = 1000, c.start_shadowed = 1001;
        c.densify_from = 50, c.densify_until = 300, c.densify_interval = 50, c.opacity_reset_interval = 200;
        c.start_regularization = 100, c.lr_position_max_steps = 400, c.background_alpha_from = 50;
        Trainer t(s.views, s.data.point_xyz, s.data.point_rgb, c);
        while (!t.done()) t.step();
        return sky_coverage(s, t.state().model);
    };
    const double paper = train("paper-fast"), fast = train("fast");
    std::printf("[ measured ] test-view sky pixels with alpha > 0.5: paper-fast %.1f %%, fast %.1f %%\n",
                100 * paper, 100 * fast);
    EXPECT_GT(paper, 0.05) << "the tiny scene no longer reproduces the sky surfels";
    EXPECT_LT(fast, 0.5 * paper);
}

// Object masks (a collection of one object): with mask_mode=object the outside of the mask is empty space,
// where nothing may be drawn; taken as transient masks it is merely ignored, and whatever the SfM points put
// there (the ground) stays. Measured on the test views: the share of pixels outside the object (its
// coverage < 0.5 in masks/) where the trained model's alpha exceeds 0.5.
TEST(TrainFloaters, ObjectMasksKeepTheOutsideEmpty) {
    static TempDir dir("train_object_masks");
    synth::SynthOptions o = synth_test::tiny_options(dir.str());
    o.object_masks = true;
    o.transient_fraction = 0;
    synth::generate_synthetic_scene(o);
    TinyScene s;
    s.root = dir.str();
    s.data = load_dataset(s.root, DatasetOptions{});
    s.views = load_train_views(s.data);
    const auto outside_coverage = [&](const std::string& mask_mode) {
        TrainConfig c = train_preset("fast");
        c.mask_mode = mask_mode;
        // Off, to compare the mask modes alone: at the end it removes the surfels that only the ignored
        // outside of transient masks sees as well (they add nothing to any kept pixel).
        c.min_contribution_pixels = 0;
        c.iterations = 300, c.warmup = 1000, c.start_shadowed = 1001;
        c.densify_from = 50, c.densify_until = 250, c.densify_interval = 50, c.opacity_reset_interval = 200;
        c.start_regularization = 100, c.lr_position_max_steps = 300;
        Trainer t(s.views, s.data.point_xyz, s.data.point_rgb, c);
        while (!t.done()) t.step();
        std::size_t outside = 0, covered = 0;
        for (const View* v : s.data.split(Split::Test)) {
            const Image mask = s.data.load_mask(*v);
            const RasterImages<float> img = render_with_environment(
                t.state().model, v->camera, ShCoeffs<float>{}, ShadingMode::Unshadowed);
            for (std::size_t p = 0; p < img.alpha.size(); ++p) {
                if (mask.pixels[p] >= 0.5f) continue;
                ++outside;
                covered += img.alpha[p] > 0.5f ? 1 : 0;
            }
        }
        return outside > 0 ? double(covered) / double(outside) : 0.0;
    };
    const double transient = outside_coverage("transient"), object = outside_coverage("object");
    std::printf(
        "[ measured ] test-view pixels outside the object with alpha > 0.5: as transient masks %.1f %%, "
        "as object masks %.1f %%\n",
        100 * transient, 100 * object);
    // The margins are wide on purpose: thread count and CPU change the summation order, and the share taken
    // as transient masks moved between 9.7 % and 11.8 % across machines.
    EXPECT_GT(transient, 0.05) << "the tiny scene no longer puts surfels outside the object";
    EXPECT_LT(object, 0.5 * transient);
}

}  // namespace
}  // namespace lumigauss
