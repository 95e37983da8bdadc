// load_trained_run (model/trained_run.h), shared by `render RUN` and `eval`: reads what a run folder holds,
// gives lighting.env_sh(i) per photo, and names the missing or inconsistent file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "lumigauss/model/ground_albedo.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/util/error.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string message_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

void write_appearance(const std::string& path, const std::vector<std::string>& names) {
    std::ofstream f(path);
    f << "{\"images\": [";
    for (std::size_t i = 0; i < names.size(); ++i)
        f << (i ? ", " : "") << "{\"name\": \"" << names[i] << "\", \"index\": " << i << "}";
    f << "]}\n";
}

// A run folder with `photos` embeddings and `names` in appearance.json.
std::string write_run(const TempDir& tmp, int photos, const std::vector<std::string>& names) {
    const std::string dir = tmp / "run";
    fs::create_directories(dir);
    const RunPaths p = run_paths(dir);
    save_relightable_ply(p.model, relight_test::random_model(testing::test_camera(), 5, 10));
    save_lighting_mlp(p.lighting, LightingMlp(photos, 11));
    write_appearance(p.appearance, names);
    return dir;
}

TEST(RelightTrainedRun, LoadsModelLightingNamesAndResolution) {
    TempDir tmp("relight_trained_run");
    const std::string dir = write_run(tmp, 2, {"x.png", "y.png"});
    {
        std::ofstream c(run_paths(dir).config);
        c << "{\"downscale\": 4, \"preset\": \"fast\"}\n";
    }
    const TrainedRun run = load_trained_run(dir);
    EXPECT_EQ(run.model.size(), 10u);
    EXPECT_EQ(run.image_names, (std::vector<std::string>{"x.png", "y.png"}));
    EXPECT_EQ(run.downscale, 4);
    EXPECT_EQ(run.find_image("y.png"), 1);
    EXPECT_EQ(run.find_image("z.png"), -1);
    const LightingMlp mlp(2, 11);
    for (int i = 0; i < 2; ++i) {
        const ShCoeffs<double> sh = run.learned_sh(i);
        const ShCoeffs<float> expected = mlp.env_sh(i);
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) EXPECT_EQ(sh.c[k][c], double(expected.c[k][c]));
    }
    EXPECT_THROW(run.learned_sh(2), Error);
}

TEST(RelightTrainedRun, SkyHorizonIsTheTrainingCamerasMeanUpWithTheConfigAngles) {
    TempDir tmp("relight_trained_run_horizon");
    const std::string dir = write_run(tmp, 2, {"x.png", "y.png"});
    {
        std::ofstream c(run_paths(dir).config);
        c << "{\"sky_background\": true, \"sky_horizon_start\": 3, \"sky_horizon_fade\": 5}\n";
    }
    // Without scene.json the run's up is unknown: no horizon, as runs trained before it.
    EXPECT_EQ(load_trained_run(dir).sky_horizon.fade_degrees, 0.0f);
    // Two level cameras of a y-down world (COLMAP style: camera y = world y), one turned 90 deg about the
    // vertical; a held-out photo looking straight down must not count.
    SceneRecord record;
    record.scene = "/nowhere", record.format = "colmap-text";
    record.photos.push_back({"x.png", "train", {1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}, {}, false});
    record.photos.push_back({"y.png", "train", {0, 0, -1, 0, 1, 0, 1, 0, 0}, {0, 0, 0}, {}, false});
    record.photos.push_back({"t.png", "test", {1, 0, 0, 0, 0, 1, 0, -1, 0}, {0, 0, 0}, {}, false});
    save_scene_record(run_paths(dir).scene, record);
    const SkyHorizon h = load_trained_run(dir).sky_horizon;
    EXPECT_EQ(h.start_degrees, 3.0f);
    EXPECT_EQ(h.fade_degrees, 5.0f);
    EXPECT_NEAR(h.up.x, 0, 1e-6);
    EXPECT_NEAR(h.up.y, -1, 1e-6);
    EXPECT_NEAR(h.up.z, 0, 1e-6);
    // The training photos' camera centres (-R^T t), the held-out photo left out.
    record.photos[1].translation = {1, 2, 3};
    save_scene_record(run_paths(dir).scene, record);
    const TrainedRun run = load_trained_run(dir);
    ASSERT_EQ(run.photo_centres.size(), 2u);
    EXPECT_EQ(length(run.photo_centres[0]), 0.0);
    EXPECT_NEAR(run.photo_centres[1].x, -3, 1e-12);  // R^T t = (3, 2, -1)
    EXPECT_NEAR(run.photo_centres[1].y, -2, 1e-12);
    EXPECT_NEAR(run.photo_centres[1].z, 1, 1e-12);
    // Trained with the ground drawn below the horizon: its albedo is read off the run's surfels, as training
    // read it.
    EXPECT_EQ(run.sky_horizon.ground_albedo.x, 0.0f);
    {
        std::ofstream c(run_paths(dir).config);
        c << "{\"sky_background\": true, \"sky_horizon_start\": 3, \"sky_horizon_fade\": 5, "
             "\"ground_backdrop\": true}\n";
    }
    const TrainedRun grounded = load_trained_run(dir);
    const Vec3f expected = ground_albedo(grounded.model, grounded.sky_horizon.up);
    EXPECT_EQ(grounded.sky_horizon.ground_albedo.x, expected.x);
    EXPECT_EQ(grounded.sky_horizon.ground_albedo.z, expected.z);
    {
        std::ofstream c(run_paths(dir).config);
        c << "{\"sky_background\": true, \"sky_horizon_start\": 3, \"sky_horizon_fade\": 5, "
             "\"ground_backdrop\": true, \"mask_mode\": \"object\"}\n";
    }
    EXPECT_EQ(load_trained_run(dir).sky_horizon.ground_albedo.x, 0.0f);  // an object's outside is empty
    // A run trained without a fade has no horizon.
    {
        std::ofstream c(run_paths(dir).config);
        c << "{\"sky_background\": true, \"sky_horizon_start\": 3, \"sky_horizon_fade\": 0}\n";
    }
    EXPECT_EQ(load_trained_run(dir).sky_horizon.fade_degrees, 0.0f);
}

// The side rule (shading/surfel_side.h) the run was trained with: config.json grazing_side_degrees about the
// training photos' up, so that every render of the run shades as training did.
TEST(RelightTrainedRun, SideRuleIsTheConfigAngleAboutTheTrainingPhotosUp) {
    TempDir tmp("relight_trained_run_sides");
    const std::string dir = write_run(tmp, 2, {"x.png", "y.png"});
    {
        std::ofstream c(run_paths(dir).config);
        c << "{\"grazing_side_degrees\": 5}\n";
    }
    // Without scene.json the up is unknown: the official rule.
    EXPECT_FALSE(load_trained_run(dir).side_rule.active());
    SceneRecord record;
    record.scene = "/nowhere", record.format = "colmap-text";
    record.photos.push_back({"x.png", "train", {1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}, {}, false});
    record.photos.push_back({"y.png", "train", {0, 0, -1, 0, 1, 0, 1, 0, 0}, {0, 0, 0}, {}, false});
    save_scene_record(run_paths(dir).scene, record);
    const SurfelSideRule rule = load_trained_run(dir).side_rule;
    EXPECT_EQ(rule.grazing_degrees, 5.0f);
    EXPECT_NEAR(rule.up.y, -1, 1e-6);  // the y-down world of these cameras
    EXPECT_NEAR(rule.up.x, 0, 1e-6);
    EXPECT_NEAR(rule.up.z, 0, 1e-6);
    // Off in the config (the paper preset), or a run trained before the key: the official rule.
    for (const char* config : {"{\"grazing_side_degrees\": 0}\n", "{}\n"}) {
        std::ofstream(run_paths(dir).config) << config;
        EXPECT_FALSE(load_trained_run(dir).side_rule.active()) << config;
    }
}

TEST(RelightTrainedRun, NamesTheMissingOrInconsistentFile) {
    TempDir tmp("relight_trained_run_bad");
    EXPECT_THAT(message_of([&] { load_trained_run(tmp / "nothing"); }), HasSubstr("not a folder"));
    const std::string dir = write_run(tmp, 2, {"x.png", "y.png", "z.png"});
    EXPECT_THAT(message_of([&] { load_trained_run(dir); }), HasSubstr("lighting.lgmlp"));
    write_appearance(run_paths(dir).appearance, {"x.png", "y.png"});
    {
        std::ofstream c(run_paths(dir).config);
        c << "{ not json";
    }
    EXPECT_THAT(message_of([&] { load_trained_run(dir); }), HasSubstr("config.json"));
    // A key of the wrong type is a damaged file, not a missing key (which older runs have).
    for (const char* bad : {"{\"sky_pins_light\": \"no\"}", "{\"sky_horizon_fade\": \"4\"}",
                            "{\"downscale\": 1.5}", "{\"mask_mode\": 1}", "[1, 2]"}) {
        std::ofstream(run_paths(dir).config) << bad;
        const std::string msg = message_of([&] { load_trained_run(dir); });
        EXPECT_THAT(msg, HasSubstr("config.json")) << bad;
        EXPECT_THAT(msg, ::testing::AnyOf(HasSubstr("must be"), HasSubstr("not a JSON object"))) << bad;
    }
    // Whether the sky shaped the lights, and the residuals' weight: recorded, else the older runs' behaviour.
    std::ofstream(run_paths(dir).config)
        << "{\"sky_pins_light\": false, \"lambda_sky_residual\": 0.25, \"lambda_sky_hemisphere\": 0.5}";
    EXPECT_FALSE(load_trained_run(dir).sky_pins_light);
    EXPECT_EQ(load_trained_run(dir).lambda_sky_residual, 0.25);
    EXPECT_EQ(load_trained_run(dir).lambda_sky_hemisphere, 0.5);
    std::ofstream(run_paths(dir).config) << "{}";
    EXPECT_TRUE(load_trained_run(dir).sky_pins_light);
    EXPECT_EQ(load_trained_run(dir).lambda_sky_residual, 0.0);
    EXPECT_EQ(load_trained_run(dir).lambda_sky_hemisphere, 0.0);
    fs::remove(run_paths(dir).config);
    EXPECT_NO_THROW(load_trained_run(dir));
    for (const char* f : {"model.ply", "lighting.lgmlp", "appearance.json"}) {
        TempDir t2("relight_trained_run_missing");
        const std::string d = write_run(t2, 2, {"x.png", "y.png"});
        fs::remove(d + "/" + f);
        const std::string msg = message_of([&] { load_trained_run(d); });
        EXPECT_THAT(msg, HasSubstr(f));
        EXPECT_THAT(msg, HasSubstr("missing"));
    }
}

}  // namespace
}  // namespace lumigauss
