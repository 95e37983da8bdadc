// `lumigauss render RUN --light L`: on a short training run of the tiny synthetic scene, every light kind
// (training photo, SH file, EXR panorama, LDR panorama with the fake HDR boost) writes every map at the
// camera's size; the shadowed PNG is the library's render; spins and orbits write numbered frames (and an
// MP4 through ffmpeg, here a stand-in script); orbit cameras read back from their JSON render the same
// image; bad input fails naming the file and leaves no output folder.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/relit_sky.h"
#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_shading.h"
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

// The tiny scene and a short run on it, shared with the other CLI tests (support/shared_tiny_run.h).
const testing::SharedTinyRun& tiny_run() {
    return testing::shared_tiny_run();
}

std::vector<const View*> test_views(const Dataset& scene) {
    return scene.split(Split::Test);
}

// A stand-in `ffmpeg` in tmp/bin: logs its arguments to tmp/ffmpeg_args.txt and writes its last argument.
std::string fake_ffmpeg_path_env(const TempDir& tmp) {
    fs::create_directories(tmp / "bin");
    const std::string script = tmp / "bin/ffmpeg";
    {
        std::ofstream f(script);
        f << "#!/bin/sh\necho \"$@\" >> " << shell_quoted(tmp / "ffmpeg_args.txt")
          << "\nfor a in \"$@\"; do last=$a; done\necho fake > \"$last\"\n";
    }
    ::chmod(script.c_str(), 0755);
    return "PATH=" + shell_quoted(tmp / "bin") + ":\"$PATH\"";
}

const std::vector<std::string> kPngMaps = {
    "shadowed", "unshadowed", "albedo", "normal", "shadow", "irradiance", "irradiance_unshadowed", "alpha"};
const std::vector<std::string> kExrMaps = {"irradiance", "depth"};

void expect_every_map(const std::string& out, const std::string& stem, int width, int height) {
    for (const std::string& m : kPngMaps) {
        const std::string path = out + "/" + stem + "_" + m + ".png";
        ASSERT_TRUE(fs::exists(path)) << path;
        const ImageInfo info = read_image_info(path);
        EXPECT_EQ(info.width, width) << path;
        EXPECT_EQ(info.height, height) << path;
        const bool gray = m == "shadow" || m == "alpha";
        EXPECT_EQ(info.channels, gray ? 1 : 3) << path;
    }
    for (const std::string& m : kExrMaps) {
        const std::string path = out + "/" + stem + "_" + m + ".exr";
        ASSERT_TRUE(fs::exists(path)) << path;
        const Image im = read_image(path);
        EXPECT_EQ(im.width, width) << path;
        EXPECT_EQ(im.height, height) << path;
    }
}

TEST(CliRelight, EveryLightKindWritesEveryMapAtTheCameraSize) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    const Dataset scene = load_dataset(t.scene);
    ASSERT_FALSE(test_views(scene).empty());
    TempDir tmp("cli_relight_kinds");
    const std::vector<std::pair<std::string, std::string>> lights = {
        {"photo", "--light train_0003.png"},
        {"sh", "--light " + shell_quoted(t.scene + "/env/sky01_sh.txt")},
        {"exr", "--light " + shell_quoted(t.scene + "/env/sky01.exr") + " --exposure 0.5"},
        {"ldr", "--light " + shell_quoted(t.scene + "/env/sky01.png") +
                    " --hdr-threshold 0.95 --hdr-scale 10 --match-exposure"},
    };
    for (const auto& [kind, light] : lights) {
        const std::string out = tmp / kind;
        const CommandResult r =
            run_lumigauss("render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) + " " +
                              light + " -o " + shell_quoted(out),
                          tmp);
        ASSERT_EQ(r.exit_code, 0) << kind << "\n" << r.output;
        for (const View* v : test_views(scene))
            expect_every_map(out, fs::path(v->name).stem().string(), v->camera.width, v->camera.height);
        // Only the test views by default.
        EXPECT_FALSE(fs::exists(out + "/train_0000_shadowed.png")) << kind;
    }
    // The boost was applied and said so.
    const CommandResult r =
        run_lumigauss("render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) + " --light " +
                          shell_quoted(t.scene + "/env/sky01.png") +
                          " --hdr-threshold 0.5 --hdr-scale 10 -o " + shell_quoted(tmp / "boost"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("fake HDR boost"));
}

// --background sky: where nothing is drawn (alpha 0), an SH light shows its sky through the SH
// (sky_colour.h), a panorama light the panorama itself along the pixel's ray (relit_sky.h); the surfels'
// pixels (alpha 1) are the plain colour.
TEST(CliRelight, SkyBackgroundShowsTheLightsSky) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    const Dataset scene = load_dataset(t.scene);
    const View& view = *test_views(scene).front();
    const std::string stem = fs::path(view.name).stem().string();
    TempDir tmp("cli_relight_sky");
    const std::string base = "render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) +
                             " --view " + shell_quoted(view.name) + " --outputs shadowed,alpha ";
    const std::string sh_file = t.scene + "/env/sky01_sh.txt", pano = t.scene + "/env/sky01.exr";
    for (const auto& [name, light] :
         {std::pair{"sh", sh_file}, std::pair{"pano", pano}, std::pair{"plain", sh_file}}) {
        const std::string background = std::string(name) == "plain" ? "" : " --background sky";
        const CommandResult r = run_lumigauss(
            base + "--light " + shell_quoted(light) + background + " -o " + shell_quoted(tmp / name), tmp);
        ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    const auto load = [&](const char* name, const char* map) {
        return read_image(tmp / name + "/" + stem + "_" + map + ".png");
    };
    const Image alpha = load("plain", "alpha"), plain = load("plain", "shadowed");
    const Image with_sh = load("sh", "shadowed"), with_pano = load("pano", "shadowed");
    // An SH sky ends below the horizon the run was trained with; a panorama is drawn as it is.
    const SkyHorizon horizon = load_trained_run(t.run).sky_horizon;
    EXPECT_GT(horizon.fade_degrees, 0.0f) << "the default preset trains with a horizon";
    const Image sh_sky = sky_image(view.camera, read_sh_text(sh_file).cast<float>(), nullptr, horizon);
    const Image pano_pixels = read_image(pano);
    int empty = 0, covered = 0;
    for (int y = 0; y < alpha.height; ++y)
        for (int x = 0; x < alpha.width; ++x) {
            if (alpha.at(x, y, 0) == 0.0f) {
                ++empty;
                const Vec3d d = pixel_ray_direction(view.camera, x, y);
                const EquirectCoord e = direction_to_equirect(d, pano_pixels.width, pano_pixels.height);
                const Vec3d radiance = sample_equirect(pano_pixels, e.row, e.col);
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(with_sh.at(x, y, c), sh_sky.at(x, y, c), 1.0 / 255);
                    EXPECT_NEAR(with_pano.at(x, y, c), sky_channel(radiance[c]), 1.0 / 255);
                }
            } else {
                // colour + (1 - alpha) sky, to the PNG's rounding (alpha and the colour are rounded too).
                ++covered;
                for (int c = 0; c < 3; ++c) {
                    const double expected =
                        plain.at(x, y, c) + (1.0 - alpha.at(x, y, 0)) * sh_sky.at(x, y, c);
                    if (expected < 0.99) {
                        EXPECT_NEAR(with_sh.at(x, y, c), expected, 3.0 / 255);
                    }
                }
            }
        }
    EXPECT_GT(empty, 20) << "no empty pixel to see the sky in";
    EXPECT_GT(covered, 20);
    const CommandResult bad = run_lumigauss(
        base + "--light " + shell_quoted(sh_file) + " --background blue -o " + shell_quoted(tmp / "bad"),
        tmp);
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_THAT(bad.output, HasSubstr("neither sky nor three numbers"));
}

TEST(CliRelight, PhotoLightRenderIsTheLibraryRender) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_relight_known");
    const std::string out = tmp / "out";
    const CommandResult r =
        run_lumigauss("render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) +
                          " --cameras all --light train_0002 -o " + shell_quoted(out) + " -q",
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const TrainedRun run = load_trained_run(t.run);
    const int index = run.find_image("train_0002.png");
    ASSERT_GE(index, 0);
    const Dataset scene = load_dataset(t.scene);
    for (const View& v : scene.views) {
        const RasterImages<float> both =
            render_with_environment(run.model, v.camera, run.lighting.env_sh(index), ShadingMode::Both,
                                    RasterBackend::Cpu, run.side_rule);  // the side rule it was trained with
        const std::string stem = fs::path(v.name).stem().string();
        const Image sh = read_image(out + "/" + stem + "_shadowed.png");
        const Image un = read_image(out + "/" + stem + "_unshadowed.png");
        ASSERT_EQ(sh.width, v.camera.width);
        double max_err = 0;
        for (std::size_t p = 0; p < sh.pixels.size() / 3; ++p)
            for (int c = 0; c < 3; ++c) {
                const double s =
                    std::clamp(double(both.color[6 * p + std::size_t(kShadowedOffset + c)]), 0.0, 1.0);
                const double u =
                    std::clamp(double(both.color[6 * p + std::size_t(kUnshadowedOffset + c)]), 0.0, 1.0);
                max_err = std::max(max_err, std::abs(double(sh.pixels[3 * p + std::size_t(c)]) - s));
                max_err = std::max(max_err, std::abs(double(un.pixels[3 * p + std::size_t(c)]) - u));
            }
        EXPECT_LE(max_err, 0.5 / 255 + 1e-5) << v.name;  // 8-bit rounding only
    }
}

TEST(CliRelight, SpinWritesNumberedFramesAndAVideo) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_relight_spin");
    const std::string env = fake_ffmpeg_path_env(tmp);
    const std::string out = tmp / "spin";
    const CommandResult r =
        run_lumigauss("render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) +
                          " --light train_0001.png --view test_0000 --spin 3 --outputs "
                          "shadowed,shadow -o " +
                          shell_quoted(out),
                      tmp, env);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (int k = 0; k < 3; ++k) {
        const std::string stem = out + "/test_0000_spin00" + std::to_string(k);
        EXPECT_TRUE(fs::exists(stem + "_shadowed.png")) << stem;
        EXPECT_TRUE(fs::exists(stem + "_shadow.png")) << stem;
        EXPECT_FALSE(fs::exists(stem + "_albedo.png")) << "not selected by --outputs";
    }
    EXPECT_FALSE(fs::exists(out + "/test_0000_spin003_shadowed.png"));
    EXPECT_FALSE(fs::exists(out + "/test_0001_spin000_shadowed.png")) << "--view keeps test_0000 only";
    EXPECT_TRUE(fs::exists(out + "/test_0000_shadowed.mp4")) << r.output;
    EXPECT_FALSE(fs::exists(out + "/test_0000_shadowed.mp4.tmp.mp4"));
    const std::string args = synth_test::read_bytes(tmp / "ffmpeg_args.txt");
    EXPECT_THAT(args, HasSubstr("test_0000_spin%03d_shadowed.png"));
    EXPECT_THAT(args, HasSubstr("-framerate 15"));

    // Frame 0 is the unturned render; frame 1 differs.
    const std::string plain = tmp / "plain";
    ASSERT_EQ(run_lumigauss("render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) +
                                " --light train_0001.png --view test_0000 --outputs shadowed -o " +
                                shell_quoted(plain),
                            tmp)
                  .exit_code,
              0);
    const std::string f0 = synth_test::read_bytes(out + "/test_0000_spin000_shadowed.png");
    EXPECT_EQ(f0, synth_test::read_bytes(plain + "/test_0000_shadowed.png"));

    // --no-video: frames only.
    const std::string quiet = tmp / "novideo";
    ASSERT_EQ(run_lumigauss(
                  "render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) +
                      " --light train_0001.png --view test_0000 --spin 2 --no-video --outputs shadowed -o " +
                      shell_quoted(quiet),
                  tmp, env)
                  .exit_code,
              0);
    EXPECT_TRUE(fs::exists(quiet + "/test_0000_spin001_shadowed.png"));
    EXPECT_FALSE(fs::exists(quiet + "/test_0000_shadowed.mp4"));
}

TEST(CliRelight, OrbitWritesATurntableWhoseCamerasReadBack) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_relight_orbit");
    const std::string env = fake_ffmpeg_path_env(tmp);
    const std::string out = tmp / "orbit";
    const CommandResult r =
        run_lumigauss("render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) + " --light " +
                          shell_quoted(t.scene + "/env/sky02_sh.txt") +
                          " --cameras orbit --frames 5 --rotate 30 -o " + shell_quoted(out),
                      tmp, env);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Dataset scene = load_dataset(t.scene);
    const Camera& first = scene.views.front().camera;
    for (int k = 0; k < 5; ++k)
        expect_every_map(out, "orbit_00" + std::to_string(k), first.width, first.height);
    EXPECT_TRUE(fs::exists(out + "/orbit_shadowed.mp4")) << r.output;
    const std::vector<NamedCamera> cams = read_camera_json(out + "/orbit_cameras.json");
    ASSERT_EQ(cams.size(), 5u);
    EXPECT_EQ(cams[2].name, "orbit_002");

    // The JSON path renders the same frame.
    const std::string again = tmp / "again";
    const CommandResult r2 = run_lumigauss(
        "render " + shell_quoted(t.run) + " --light " + shell_quoted(t.scene + "/env/sky02_sh.txt") +
            " --cameras " + shell_quoted(out + "/orbit_cameras.json") +
            " --view orbit_002 --rotate 30 --outputs shadowed -o " + shell_quoted(again),
        tmp);
    ASSERT_EQ(r2.exit_code, 0) << r2.output;
    EXPECT_EQ(synth_test::read_bytes(again + "/orbit_002_shadowed.png"),
              synth_test::read_bytes(out + "/orbit_002_shadowed.png"));
    EXPECT_FALSE(fs::exists(again + "/orbit_001_shadowed.png"));
}

TEST(CliRelight, BadInputNamesTheFileAndWritesNothing) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_relight_errors");
    const std::string out = tmp / "out";
    const std::string base = "render " + shell_quoted(t.run) + " --scene " + shell_quoted(t.scene) + " -o " +
                             shell_quoted(out) + " ";

    // A run folder without model.ply.
    const std::string broken = tmp / "broken_run";
    fs::create_directories(broken);
    for (const char* f : {"lighting.lgmlp", "appearance.json", "config.json"})
        fs::copy_file(t.run + "/" + f, broken + "/" + f);
    // A run from before runs recorded their scene: scene cameras need --scene.
    const std::string unrecorded = tmp / "unrecorded_run";
    fs::copy(t.run, unrecorded, fs::copy_options::recursive);
    fs::remove(unrecorded + "/scene.json");
    {
        std::ofstream bad(tmp / "bad.png");
        bad << "not an image";
        std::ofstream cams(tmp / "cams.json");
        cams << R"([{"name": "a", "width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 4, "cy": 3,
                     "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]},
                    {"name": "b", "width": 8, "height": 6, "fy": 5, "cx": 4, "cy": 3,
                     "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 2]}])";
    }
    struct Case {
        std::string args;
        std::vector<std::string> expect;
    };
    const std::vector<Case> cases = {
        {base + "--light no_such_photo", {"no_such_photo", "train_0000.png", "appearance.json"}},
        {"render " + shell_quoted(broken) + " --scene " + shell_quoted(t.scene) + " -o " + shell_quoted(out) +
             " --light train_0000.png",
         {"model.ply", "missing"}},
        {base + "--light " + shell_quoted(tmp / "bad.png"), {"bad.png"}},
        {base + "--light " + shell_quoted(tmp / "missing.exr"), {"missing.exr"}},
        {base + "--light train_0000.png --cameras " + shell_quoted(tmp / "cams.json"),
         {"cams.json", "cameras[1]", "fx"}},
        {base + "--light train_0000.png --cameras nowhere.json", {"nowhere.json"}},
        {"render " + shell_quoted(unrecorded) + " --light train_0000.png --cameras orbit -o " +
             shell_quoted(out),
         {"--scene", "scene.json"}},
        {base + "--light train_0000.png --view nope", {"nope", "test_0000"}},
        {base + "--light train_0000.png --up sideways", {"sideways"}},
        {base + "--light train_0000.png --outputs shadowed,colour", {"colour"}},
        {base + "--light train_0000.png --cameras orbit --spin 4", {"--spin"}},
        {base, {"--light"}},
        {"render --scene " + shell_quoted(t.scene) + " -o " + shell_quoted(out), {"--ply"}},
    };
    for (const Case& c : cases) {
        const CommandResult r = run_lumigauss(c.args, tmp);
        EXPECT_NE(r.exit_code, 0) << c.args << "\n" << r.output;
        for (const std::string& e : c.expect) EXPECT_THAT(r.output, HasSubstr(e)) << c.args;
        EXPECT_FALSE(fs::exists(out)) << "an output folder after: " << c.args;
    }
}

}  // namespace
}  // namespace lumigauss
