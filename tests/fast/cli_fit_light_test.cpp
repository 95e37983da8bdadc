// `lumigauss fit-light`: on a short training run of the tiny synthetic scene, a test photo re-rendered by
// the run under a known SH file is fitted back (by camera name with --scene, and by camera JSON), the SH
// file written reproduces the photo, and bad input fails naming the problem without writing output.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/image_metrics.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/light_fit.h"
#include "lumigauss/shading/sh_text.h"
#include "support/run_cli.h"
#include "support/shared_tiny_run.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using testing::CommandResult;
using ::testing::HasSubstr;
using testing::run_lumigauss;
using testing::shell_quoted;
namespace fs = std::filesystem;

// The tiny scene, a 30-iteration run on it, and one test view re-rendered under a known light.
struct FitSetup {
    TempDir dir{"cli_fit_light"};
    std::string scene = dir / "scene", run = dir / "run", photo = dir / "photo.png";
    CommandResult train;
    View view;
    ShCoeffs<double> light;
    FitSetup() {
        synth::generate_synthetic_scene(synth_test::tiny_options(scene));
        // Lights that start at a uniform radiance: after 30 iterations from the official random start the
        // renders were nearly black (mean 0.015), and which fit came closer was decided by noise. The sky
        // is the light's alone and pins it (fast gives it a residual free of the light), so that the whole
        // photo, its sky too, tells the light, and the light file alone redraws the photo.
        train = run_lumigauss("train " + shell_quoted(scene) + " -o " + shell_quoted(run) +
                                  " --preset fast --iterations 30 -q --set lighting_init_radiance=0.5"
                                  " --set sky_pins_light=true --set sky_residual=false",
                              dir);
        if (train.exit_code != 0) return;
        const TrainedRun r = load_trained_run(run);
        DatasetOptions dopt;
        dopt.downscale = r.downscale > 0 ? r.downscale : 1;
        const Dataset d = load_dataset(scene, dopt);
        view = *d.split(Split::Test).front();
        // A light unlike the training ones in colour and direction: 1.3 x photo 0's, tinted, turned.
        light = r.learned_sh(0);
        for (int k = 0; k < kShCount; ++k)
            light.c[k] = Vec3d{1.3 * light.c[k][0], 1.1 * light.c[k][1], 0.8 * light.c[k][2]};
        std::swap(light.c[1], light.c[3]);
        write_png(photo, rendered(r, view.camera, light));
    }
    // As the run draws a photo: trained with its sky behind the surfels, the light's sky fills the rest.
    static Image rendered(const TrainedRun& r, const Camera& cam, const ShCoeffs<double>& sh) {
        return fitted_colour(
            r, cam, render_with_environment(r.model, cam, sh.cast<float>(), ShadingMode::Shadowed), 0, sh);
    }
    // PSNR over the whole image, of the run rendered under `sh` against the photo.
    double psnr_with(const ShCoeffs<double>& sh) const {
        const TrainedRun r = load_trained_run(run);
        const Image a = rendered(r, view.camera, sh), b = read_image(photo);
        return psnr_from_mse(masked_mse(a, to_channels(b, 3), Image(a.width, a.height, 1, 1.0f)));
    }
};

const FitSetup& setup() {
    static FitSetup s;
    return s;
}

TEST(CliFitLight, FitsATestPhotoByCameraName) {
    const FitSetup& s = setup();
    ASSERT_EQ(s.train.exit_code, 0) << s.train.output;
    TempDir tmp("cli_fit_light_name");
    const std::string out = tmp / "fitted.txt", render = tmp / "fitted.png";
    const CommandResult r = run_lumigauss(
        "fit-light " + shell_quoted(s.run) + " --scene " + shell_quoted(s.scene) + " --camera " +
            shell_quoted(s.view.name) + " --image " + shell_quoted(s.photo) +
            " --via sh --iterations 300 -o " + shell_quoted(out) + " --render " + shell_quoted(render),
        tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("fit-light: masked PSNR"));
    ASSERT_TRUE(fs::exists(render));
    const ShCoeffs<double> fitted = read_sh_text(out);
    EXPECT_GT(s.psnr_with(fitted), 40.0);
}

// A `fast` run's skies are residuals free of its lights: the fit says that the photo's residual is written
// with the light and that the light comes from the surfels alone.
TEST(CliFitLight, SaysWhenTheRunsSkyIsFreeOfItsLight) {
    const testing::SharedTinyRun& tiny = testing::shared_tiny_run();
    ASSERT_EQ(tiny.exit_code, 0) << tiny.output;
    TempDir tmp("cli_fit_light_free_sky");
    const std::string out = tmp / "fitted.txt";
    const CommandResult r =
        run_lumigauss("fit-light " + shell_quoted(tiny.run) + " --scene " + shell_quoted(tiny.scene) +
                          " --camera test_0000.png --iterations 10 -o " + shell_quoted(out),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("is written with the light"));
    EXPECT_THAT(r.output, HasSubstr("sky_pins_light=false"));
    EXPECT_TRUE(fs::exists(out));
    // The run the other tests train has no residual: nothing to say, nothing but the light in the file.
    const FitSetup& s = setup();
    ASSERT_EQ(s.train.exit_code, 0) << s.train.output;
    const std::string pinned_out = tmp / "pinned.txt";
    const CommandResult pinned =
        run_lumigauss("fit-light " + shell_quoted(s.run) + " --scene " + shell_quoted(s.scene) +
                          " --camera " + shell_quoted(s.view.name) + " --image " + shell_quoted(s.photo) +
                          " --iterations 10 -o " + shell_quoted(pinned_out),
                      tmp);
    ASSERT_EQ(pinned.exit_code, 0) << pinned.output;
    EXPECT_THAT(pinned.output, ::testing::Not(HasSubstr("is written with the light")));
    EXPECT_FALSE(read_sh_text_light(pinned_out).sky_residual.has_value());
}

// The photo's residual travels in the light file ("#sky" rows): `render --light FILE --background sky`
// draws the photo's sky as the fit drew it (`fit-light --render`); the same file without those rows shows
// the light's own sky, which a free-light run never fitted to the photo.
TEST(CliFitLight, TheLightFileDrawsThePhotosSky) {
    const testing::SharedTinyRun& tiny = testing::shared_tiny_run();
    ASSERT_EQ(tiny.exit_code, 0) << tiny.output;
    TempDir tmp("cli_fit_light_sky_rows");
    const std::string out = tmp / "fitted.txt", bare = tmp / "bare.txt", fit_png = tmp / "fit.png";
    const CommandResult fit =
        run_lumigauss("fit-light " + shell_quoted(tiny.run) + " --scene " + shell_quoted(tiny.scene) +
                          " --camera test_0000.png --iterations 30 -q -o " + shell_quoted(out) +
                          " --render " + shell_quoted(fit_png),
                      tmp);
    ASSERT_EQ(fit.exit_code, 0) << fit.output;
    ASSERT_TRUE(read_sh_text_light(out).sky_residual.has_value());
    std::istringstream lines(synth_test::read_bytes(out));
    std::ofstream bare_file(bare);
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("#sky", 0) != 0) bare_file << line << "\n";
    bare_file.close();
    const auto render = [&](const std::string& light, const std::string& name,
                            const std::string& extra = "") {
        const CommandResult r =
            run_lumigauss("render " + shell_quoted(tiny.run) + " --scene " + shell_quoted(tiny.scene) +
                              " --view test_0000.png --outputs shadowed,alpha --background sky -q --light " +
                              shell_quoted(light) + " -o " + shell_quoted(tmp / name) + extra,
                          tmp);
        EXPECT_EQ(r.exit_code, 0) << r.output;
        return std::pair{read_image(tmp / name + "/test_0000_shadowed.png"),
                         read_image(tmp / name + "/test_0000_alpha.png")};
    };
    const auto [with_sky, alpha] = render(out, "with");
    const Image without_sky = render(bare, "bare").first, fitted = read_image(fit_png);
    // A turned light turns its residual with it (it was dropped before): a full turn draws the same sky.
    const Image turned = render(out, "turned", " --rotate 360").first;
    ASSERT_EQ(fitted.width, with_sky.width);
    int empty = 0;
    double with_err = 0, without_err = 0, turned_err = 0;
    for (int y = 0; y < alpha.height; ++y)
        for (int x = 0; x < alpha.width; ++x) {
            if (alpha.at(x, y, 0) != 0.0f) continue;
            ++empty;
            for (int c = 0; c < 3; ++c) {
                with_err = std::max(with_err, double(std::abs(with_sky.at(x, y, c) - fitted.at(x, y, c))));
                turned_err = std::max(turned_err, double(std::abs(turned.at(x, y, c) - fitted.at(x, y, c))));
                without_err =
                    std::max(without_err, double(std::abs(without_sky.at(x, y, c) - fitted.at(x, y, c))));
            }
        }
    ASSERT_GT(empty, 20) << "no empty pixel to see the sky in";
    EXPECT_LE(with_err, 1.5 / 255);
    EXPECT_LE(turned_err, 2.5 / 255);
    EXPECT_GT(without_err, 5.0 / 255);
}

TEST(CliFitLight, FitsThroughTheEmbeddingWithACameraJson) {
    const FitSetup& s = setup();
    ASSERT_EQ(s.train.exit_code, 0) << s.train.output;
    TempDir tmp("cli_fit_light_json");
    const std::string cams = tmp / "pose.json", out = tmp / "fitted.txt";
    write_camera_json(cams, {{"photo", s.view.camera}});
    const CommandResult r =
        run_lumigauss("fit-light " + shell_quoted(s.run) + " --camera " + shell_quoted(cams) + " --image " +
                          shell_quoted(s.photo) + " --iterations 150 -q -o " + shell_quoted(out),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // The default for a run is the embedding; the render must improve on the mean training light.
    const TrainedRun run = load_trained_run(s.run);
    const ShCoeffs<double> mean = default_initial_sh(run);  // the mean learned light
    EXPECT_GT(s.psnr_with(read_sh_text(out)), s.psnr_with(mean) + 3.0);
}

// The scene's cameras given a lens (OPENCV, k1 = -0.2): fitting by camera name uses the photo undistorted as
// training does, the same as passing the lens photo and its mask with --image/--mask, and not the photo as
// if taken by the pinhole (which fit-light did while the mask was already undistorted).
TEST(CliFitLight, ALensCameraFitsTheUndistortedPhoto) {
    const FitSetup& s = setup();
    ASSERT_EQ(s.train.exit_code, 0) << s.train.output;
    TempDir tmp("cli_fit_light_lens");
    const std::string lens = tmp / "lens";
    fs::copy(s.scene, lens, fs::copy_options::recursive);
    std::string cameras;
    std::istringstream lines(synth_test::read_bytes(lens + "/sparse/0/cameras.txt"));
    for (std::string line; std::getline(lines, line);) {
        if (const std::size_t at = line.find(" PINHOLE "); at != std::string::npos)
            line = line.replace(at, 9, " OPENCV ") + " -0.2 0 0 0";
        cameras += line + "\n";
    }
    std::ofstream(lens + "/sparse/0/cameras.txt", std::ios::binary) << cameras;
    const auto fit = [&](const std::string& scene, const std::string& extra, const std::string& out) {
        const CommandResult r = run_lumigauss(
            "fit-light " + shell_quoted(s.run) + " --scene " + shell_quoted(scene) + " --camera " +
                shell_quoted(s.view.name) + extra + " --via sh --iterations 100 -q -o " + shell_quoted(out),
            tmp);
        EXPECT_EQ(r.exit_code, 0) << r.output;
        return synth_test::read_bytes(out);
    };
    const std::string by_name = fit(lens, "", tmp / "name.txt");
    const std::string mask =
        s.view.mask_path.empty()
            ? ""
            : " --mask " + shell_quoted(lens + "/masks/" + fs::path(s.view.mask_path).filename().string());
    const std::string by_image =
        fit(lens, " --image " + shell_quoted(lens + "/images/" + s.view.name) + mask, tmp / "image.txt");
    const std::string pinhole = fit(s.scene, "", tmp / "pinhole.txt");
    ASSERT_FALSE(by_name.empty());
    EXPECT_EQ(by_name, by_image);
    EXPECT_NE(by_name, pinhole);
}

TEST(CliFitLight, BadInputFailsNamingTheProblem) {
    const FitSetup& s = setup();
    ASSERT_EQ(s.train.exit_code, 0) << s.train.output;
    TempDir tmp("cli_fit_light_bad");
    const std::string out = tmp / "never.txt";
    const std::string base = "fit-light " + shell_quoted(s.run) + " -o " + shell_quoted(out) + " ";
    CommandResult r =
        run_lumigauss(base + "--scene " + shell_quoted(s.scene) + " --camera no_such_image", tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("no_such_image"));
    r = run_lumigauss(base + "--camera " + shell_quoted(s.view.name), tmp);  // a name needs --scene
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("--scene"));
    r = run_lumigauss(base + "--scene " + shell_quoted(s.scene) + " --camera " + shell_quoted(s.view.name) +
                          " --image " + shell_quoted(tmp / "missing.png"),
                      tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("missing.png"));
    Image wide(s.view.camera.width * 2, s.view.camera.height, 3, 0.5f);  // another aspect ratio
    write_png(tmp / "wide.png", wide);
    r = run_lumigauss(base + "--scene " + shell_quoted(s.scene) + " --camera " + shell_quoted(s.view.name) +
                          " --image " + shell_quoted(tmp / "wide.png"),
                      tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("aspect ratio"));
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace lumigauss
