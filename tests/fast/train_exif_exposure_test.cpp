// The photos' EXIF exposure as the lighting's starting point (config exif_exposure): the factors, the
// environment each photo is rendered under, the lighting gradient through the factor (finite differences),
// the bit-identical run when every factor is 1, and the factors saved with the run and used by every reader
// of a training photo's light.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "lumigauss/model/run_files.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/train/trainer.h"
#include "trainer_test_util.h"

namespace lumigauss {
namespace {

using namespace trainer_test;

// The tiny scene's training photos with EXIF exposure values 10, 11, 10, 11, ... (factors 2^(+-0.5) about
// their mean).
std::vector<TrainView> views_with_exposures() {
    std::vector<TrainView> views = tiny_scene().views;
    for (std::size_t i = 0; i < views.size(); ++i) views[i].ev100 = 10.0 + double(i % 2);
    return views;
}

TEST(ExifExposure, FactorsAreRelativeToTheMeanExposureValue) {
    std::vector<TrainView> views(4);
    views[0].ev100 = 10, views[1].ev100 = 11, views[2].ev100 = 12;  // views[3]: no EXIF
    const std::vector<float> k = exif_exposure_factors(views);
    EXPECT_FLOAT_EQ(k[0], 2.0f);  // one stop more light than the mean (EV 11)
    EXPECT_FLOAT_EQ(k[1], 1.0f);
    EXPECT_FLOAT_EQ(k[2], 0.5f);
    EXPECT_FLOAT_EQ(k[3], 1.0f);
    EXPECT_EQ(exif_exposure_factors(std::vector<TrainView>(3)), std::vector<float>(3, 1.0f));
}

TEST(ExifExposure, EachPhotoIsRenderedUnderItsFactorTimesTheNetworkOutput) {
    TrainConfig config = shrunk_config();
    config.exif_exposure = true;
    const TinyScene& s = tiny_scene();
    const Trainer t(views_with_exposures(), s.data.point_xyz, s.data.point_rgb, config);
    for (int i = 0; i < 2; ++i) {
        const float k = t.exposures()[std::size_t(i)];
        EXPECT_NEAR(k, i % 2 == 0 ? std::sqrt(2.0f) : 1.0f / std::sqrt(2.0f), 1e-6f);
        const ShCoeffs<float> out = t.state().lighting.env_sh(i), env = t.environment(i);
        for (int c = 0; c < kShCount; ++c) EXPECT_EQ(env.c[c].x, k * out.c[c].x);
    }
    config.exif_exposure = false;
    const Trainer off(views_with_exposures(), s.data.point_xyz, s.data.point_rgb, config);
    EXPECT_EQ(off.exposures(), std::vector<float>(s.views.size(), 1.0f)) << "off unless asked for";
}

// The lighting gradient of one step through the factor, against central differences of the step's loss in
// the network's output bias (the DC of red and a degree-1 coefficient of blue).
TEST(ExifExposure, LightingGradientMatchesFiniteDifferences) {
    TrainConfig config = shrunk_config();
    config.exif_exposure = true;
    config.env_noise_sigma = 0;
    const TinyScene& s = tiny_scene();
    const std::vector<TrainView> views = views_with_exposures();
    const TrainState start = Trainer(views, s.data.point_xyz, s.data.point_rgb, config).state();
    Trainer analytic(views, start);
    (void)analytic.step();
    ASSERT_NE(analytic.exposures()[std::size_t(analytic.view_for_iteration(1))], 1.0f);
    for (const int output : {env_sh_output(0, 0), env_sh_output(2, 2)}) {
        const double h =
            0.002;  // 0.02 already crosses the loss's kinks (a 40 % error with or without exposure)
        double total[2];
        for (int side = 0; side < 2; ++side) {
            TrainState moved = start;
            moved.lighting.param(MlpGroup::kB3)[std::size_t(output)] += float(side == 0 ? h : -h);
            Trainer t(views, std::move(moved));
            total[side] = t.step().total;
        }
        const double numeric = (total[0] - total[1]) / (2 * h);
        const double exact = analytic.lighting_gradients()[MlpGroup::kB3][std::size_t(output)];
        EXPECT_NEAR(exact, numeric, 0.03 * std::abs(numeric) + 1e-6) << "output " << output;
    }
}

TEST(ExifExposure, FactorsOfOneTrainBitForBitAsWithout) {
    TrainConfig config = shrunk_config();
    config.iterations = 12;
    const TinyScene& s = tiny_scene();
    std::vector<TrainView> equal = s.views;
    for (TrainView& v : equal) v.ev100 = 11.5;  // every factor exactly 1
    Trainer without(s.views, s.data.point_xyz, s.data.point_rgb, config);
    config.exif_exposure = true;
    Trainer with(equal, s.data.point_xyz, s.data.point_rgb, config);
    while (!without.done()) (void)without.step(), (void)with.step();
    for (int p = 0; p < kModelParamCount; ++p) {
        const auto& a = without.state().model.param(ModelParam(p));
        const auto& b = with.state().model.param(ModelParam(p));
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0) << p;
    }
}

TEST(ExifExposure, TheRunSavesTheFactorsAndItsReadersApplyThem) {
    TrainConfig config = shrunk_config();
    config.exif_exposure = true;
    const TinyScene& s = tiny_scene();
    const Trainer t(views_with_exposures(), s.data.point_xyz, s.data.point_rgb, config);
    TempDir dir("train_exif_exposure_run");
    const RunPaths paths = run_paths(dir.str());
    const std::vector<double> k(t.exposures().begin(), t.exposures().end());
    save_run_model(paths, t.state().model, t.state().lighting, t.state().image_names, SkyResiduals{}, k);
    EXPECT_EQ(load_appearance_exposures(paths.appearance), k);
    const TrainedRun run = load_trained_run(dir.str());
    for (int i = 0; i < 2; ++i) {
        const ShCoeffs<double> learned = run.learned_sh(i);
        const ShCoeffs<float> env = t.environment(i);
        EXPECT_NEAR(learned.c[0].y, double(env.c[0].y), 1e-6 * std::abs(double(env.c[0].y)) + 1e-9);
    }
    // A run without the key reads 1 for every photo; a bad value is refused naming the file.
    save_appearance(paths.appearance, t.state().image_names);
    EXPECT_EQ(load_appearance_exposures(paths.appearance), std::vector<double>(k.size(), 1.0));
    std::string bad = synth_test::read_bytes(paths.appearance);
    bad.replace(bad.find("\"index\": 0"), 10, "\"index\": 0, \"exposure\": -1");
    std::ofstream(paths.appearance, std::ios::binary | std::ios::trunc) << bad;
    EXPECT_THROW(load_appearance_exposures(paths.appearance), Error);
}

}  // namespace
}  // namespace lumigauss
