// The holdout protocol (eval/holdout.h): the masks split each photo into a left half to fit and a right half
// to score; on a copy of the tiny scene whose test photos are the run's own renders under one known light,
// the light fitted on the left half reproduces the right half (so the right half scores high), while a
// photo whose right half was changed scores low there although the fit on the left is as good as before.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "lumigauss/eval/holdout.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/image_metrics.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/light_fit.h"
#include "lumigauss/util/error.h"
#include "support/run_cli.h"
#include "support/shared_tiny_run.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using testing::run_lumigauss;
using testing::shell_quoted;
namespace fs = std::filesystem;

TEST(HoldoutMasks, LeftHalfFitsRightHalfScores) {
    Image scene_mask(10, 8, 1, 1.0f);
    scene_mask.at(1, 4, 0) = 0.3f;  // soft value on the left: kept as it is for the fit
    scene_mask.at(7, 4, 0) = 0.3f;  // on the right: below 0.5, a hole in the score mask
    const Image fit = holdout_fit_mask(scene_mask, 10, 8);
    const Image score = holdout_score_mask(scene_mask, 10, 8);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 10; ++x) {
            EXPECT_EQ(fit.at(x, y, 0), x < 5 ? scene_mask.at(x, y, 0) : 0.0f) << x << "," << y;
            if (x < 5) {
                EXPECT_EQ(score.at(x, y, 0), 0.0f);
            }
        }
    // The score mask is eroded 5x5 as cv2.erode (the image border does not erode): pixels within 2 of the
    // hole are out, the others in.
    EXPECT_EQ(score.at(7, 4, 0), 0.0f);
    EXPECT_EQ(score.at(9, 2, 0), 0.0f);
    EXPECT_EQ(score.at(5, 6, 0), 0.0f);
    EXPECT_EQ(score.at(7, 1, 0), 1.0f);
    EXPECT_EQ(score.at(9, 7, 0), 1.0f);
    EXPECT_EQ(score.at(5, 0, 0), 1.0f);
    // A sky mask takes the sky out of the score, eroded like the rest (NeRF-OSR's evaluation masks).
    Image sky(10, 8, 1, 0.0f);
    sky.at(9, 0, 0) = 1.0f;
    const Image no_sky = holdout_score_mask(scene_mask, 10, 8, sky);
    EXPECT_EQ(no_sky.at(9, 0, 0), 0.0f);
    EXPECT_EQ(no_sky.at(7, 1, 0), 0.0f);  // within 2 of the sky
    EXPECT_EQ(no_sky.at(5, 0, 0), 1.0f);
    EXPECT_EQ(no_sky.at(9, 7, 0), 1.0f);
    EXPECT_THROW(holdout_score_mask(scene_mask, 10, 8, Image(9, 8, 1, 0.0f)), Error);
    // Without a scene mask: all ones, split the same way.
    const Image none = holdout_fit_mask(Image{}, 10, 8);
    EXPECT_EQ(none.at(4, 3, 0), 1.0f);
    EXPECT_EQ(none.at(5, 3, 0), 0.0f);
    EXPECT_THROW(holdout_fit_mask(Image(9, 8, 1, 1.0f), 10, 8), Error);
}

// The tiny scene and a short run on it (shared with the CLI tests: support/shared_tiny_run.h), and a copy of
// the scene whose test photos are the run's renders (over the sky of the light, as the run draws them).
struct HoldoutScene {
    TempDir dir{"eval_holdout"};
    std::string scene = testing::shared_tiny_run().scene, run_dir = testing::shared_tiny_run().run;
    std::string copy = dir / "copy";
    bool ok = false;
    ShCoeffs<double> light;
    HoldoutScene() {
        if (testing::shared_tiny_run().exit_code != 0) return;
        fs::copy(scene, copy, fs::copy_options::recursive);
        const TrainedRun run = load_trained_run(run_dir);
        light = run.learned_sh(1);
        const Dataset d = load_dataset(copy, {});
        // As the run draws them: the tiny run is trained with its sky behind the surfels, so the sky of the
        // light fills what they leave uncovered.
        for (const View* v : d.split(Split::Test))
            write_png(v->image_path,
                      fitted_colour(
                          run, v->camera,
                          render_with_environment(run.model, v->camera, light.cast<float>(),
                                                  ShadingMode::Shadowed, RasterBackend::Cpu, run.side_rule),
                          0, light));
        ok = true;
    }
};

const HoldoutScene& holdout_scene() {
    static HoldoutScene s;
    return s;
}

// PSNR of the shadowed panel on the score mask's pixels that the surfels cover (alpha > 0.5 under the
// fitted light): what the fitted light reproduces, without the sky drawn behind.
double covered_psnr(const TrainedRun& run, const View& view, const HoldoutImageResult& im) {
    const RasterImages<float> r =
        render_with_environment(run.model, view.camera, im.light.cast<float>(), ShadingMode::Shadowed,
                                RasterBackend::Cpu, run.side_rule);
    Image covered = im.panels.mask;
    for (std::size_t p = 0; p < covered.pixels.size(); ++p)
        if (r.alpha[p] <= 0.5f) covered.pixels[p] = 0.0f;
    return psnr_from_mse(masked_mse(im.panels.shadowed, im.panels.truth, covered));
}

HoldoutOptions quick_options() {
    HoldoutOptions o;
    o.fit.variable = LightVariable::Sh;
    o.fit.iterations = 150;
    return o;
}

TEST(Holdout, TheFittedLightReproducesTheUnseenHalf) {
    const HoldoutScene& s = holdout_scene();
    ASSERT_TRUE(s.ok);
    const TrainedRun run = load_trained_run(s.run_dir);
    const Dataset d = load_dataset(s.copy, {});
    const HoldoutResult r = evaluate_holdout(run, d, quick_options());
    ASSERT_EQ(r.images.size(), d.split(Split::Test).size());
    // The tiny run (`fast`) learned its photos' skies as residuals free of their lights
    // (sky_pins_light=false), so the fit takes the light from the surfels alone: on the right half, what the
    // surfels cover is reproduced by the light; what they leave uncovered shows the sky the left half's
    // residual extrapolates. When the sky pulled the fitted light as well, the light was bent by it and the
    // covered right half of test_0001 scored 27.7 dB.
    ASSERT_FALSE(run.sky_pins_light);
    for (std::size_t i = 0; i < r.images.size(); ++i) {
        const HoldoutImageResult& im = r.images[i];
        EXPECT_GT(im.fit_pixels, 0u);
        EXPECT_GT(im.score_pixels, 0u);
        EXPECT_GT(im.fit_psnr, 35.0) << im.name;
        EXPECT_GT(im.fit_psnr_unshadowed, 15.0) << im.name;  // an unshadowed fit of a shadowed photo
        EXPECT_GT(covered_psnr(run, *d.split(Split::Test)[i], im), 35.0) << im.name;
        std::printf("PROBE %s covered %.2f protocol %.2f ssim %.3f\n", im.name.c_str(),
                    covered_psnr(run, *d.split(Split::Test)[i], im), im.shadowed.psnr, im.shadowed.ssim);
        EXPECT_GT(im.shadowed.psnr, 20.0) << im.name;
        EXPECT_EQ(im.panels.shadowed.width, im.panels.truth.width);
    }
    EXPECT_GT(r.mean_shadowed.psnr, 28.0);

    // At most one photo: the first of the split, scored as before.
    HoldoutOptions one = quick_options();
    one.max_views = 1;
    const HoldoutResult first = evaluate_holdout(run, d, one);
    ASSERT_EQ(first.images.size(), 1u);
    EXPECT_EQ(first.images[0].name, r.images[0].name);
    EXPECT_EQ(first.images[0].shadowed.psnr, r.images[0].shadowed.psnr);

    // Without the unshadowed fit (what `train` scores): the same shadowed scores, no unshadowed ones.
    HoldoutOptions shadowed_only = quick_options();
    shadowed_only.unshadowed = false;
    const HoldoutResult s1 = evaluate_holdout(run, d, shadowed_only);
    ASSERT_EQ(s1.images.size(), r.images.size());
    for (std::size_t i = 0; i < r.images.size(); ++i) {
        EXPECT_EQ(s1.images[i].shadowed.psnr, r.images[i].shadowed.psnr);
        EXPECT_TRUE(std::isnan(s1.images[i].unshadowed.psnr));
        EXPECT_TRUE(std::isnan(s1.images[i].fit_psnr_unshadowed));
    }
}

TEST(Holdout, OnlyTheRightHalfIsScored) {
    const HoldoutScene& s = holdout_scene();
    ASSERT_TRUE(s.ok);
    const TrainedRun run = load_trained_run(s.run_dir);
    TempDir tmp("eval_holdout_changed");
    const std::string changed = tmp / "scene";
    fs::copy(s.copy, changed, fs::copy_options::recursive);
    const Dataset d = load_dataset(changed, {});
    const View& v = *d.split(Split::Test).front();
    Image photo = read_image(v.image_path);
    for (int y = 0; y < photo.height; ++y)
        for (int x = photo.width / 2; x < photo.width; ++x)
            for (int c = 0; c < photo.channels; ++c) photo.at(x, y, c) = 1.0f - photo.at(x, y, c);
    write_png(v.image_path, photo);
    const HoldoutResult r = evaluate_holdout(run, d, quick_options());
    const HoldoutImageResult& im = r.images.front();
    EXPECT_GT(im.fit_psnr, 35.0);       // the left half is untouched: fitted as well as before
    EXPECT_LT(im.shadowed.psnr, 20.0);  // the right half is what is scored
}

TEST(Holdout, CliWritesTheReport) {
    const HoldoutScene& s = holdout_scene();
    ASSERT_TRUE(s.ok);
    TempDir tmp("eval_holdout_cli");
    const std::string report = tmp / "report";
    const testing::CommandResult r =
        run_lumigauss("eval " + shell_quoted(s.run_dir) + " --scene " + shell_quoted(s.copy) +
                          " --protocol holdout --via sh --fit-iterations 100 -o " + shell_quoted(report),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("eval-summary: shadowed_psnr="), std::string::npos) << r.output;
    const nlohmann::json m = synth_test::read_json(report + "/metrics.json");
    EXPECT_EQ(m["protocol"], "holdout");
    EXPECT_EQ(m["fit"]["variable"], "sh");
    EXPECT_EQ(m["fit"]["iterations"], 100);
    const Dataset d = load_dataset(s.copy, {});
    const std::vector<const View*> tests = d.split(Split::Test);
    ASSERT_EQ(m["images"].size(), tests.size());
    EXPECT_GT(m["mean"]["shadowed"]["psnr"].get<double>(), 30.0);
    // Progress: one line per photo as its fit ends (a collection takes minutes).
    const std::string last = "[" + std::to_string(tests.size()) + "/" + std::to_string(tests.size()) + " ";
    EXPECT_NE(r.output.find("[1/" + std::to_string(tests.size()) + " "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(last), std::string::npos) << r.output;
    for (const View* v : tests) {
        fs::path stem = fs::path(v->name);
        stem.replace_extension();
        EXPECT_TRUE(fs::exists(report + "/sheets/" + stem.string() + ".png")) << v->name;
        EXPECT_TRUE(fs::exists(report + "/env/" + stem.string() + "_sh.txt")) << v->name;
        EXPECT_TRUE(fs::exists(report + "/env/" + stem.string() + "_unshadowed_sh.txt")) << v->name;
    }
    EXPECT_TRUE(fs::exists(report + "/report.md"));
}

}  // namespace
}  // namespace lumigauss
