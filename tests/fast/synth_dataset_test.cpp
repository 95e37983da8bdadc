// The generated dataset is what a user brings (the project's loader reads it) and carries ground truth in
// data/plaza's layout; its points sit on the surfaces they were sampled from.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/synth/camera_paths.h"
#include "lumigauss/synth/world.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
namespace fs = std::filesystem;

// One tiny dataset per test process (each gtest case runs in its own process under CTest).
const std::string& tiny_dataset() {
    static TempDir dir("synth_dataset");
    static const std::string root = [] {
        synth::generate_synthetic_scene(synth_test::tiny_options(dir.str()));
        return dir.str();
    }();
    return root;
}

TEST(SynthDataset, LoadsWithTheProjectLoader) {
    const std::string root = tiny_dataset();
    const Dataset d = load_dataset(root, DatasetOptions{});
    const auto meta = synth_test::read_json(root + "/meta.json");
    ASSERT_EQ(d.views.size(), meta["images"].size());
    EXPECT_EQ(d.split(Split::Train).size(), 8u);
    EXPECT_EQ(d.split(Split::Test).size(), 2u);
    EXPECT_FALSE(d.point_xyz.empty());
    EXPECT_EQ(int(d.point_xyz.size()), meta["n_points3D"].get<int>());
    for (const auto& im : meta["images"]) {
        const std::string name = im["name"];
        const View* view = nullptr;
        for (const View& v : d.views)
            if (v.name == name) view = &v;
        ASSERT_NE(view, nullptr) << name;
        EXPECT_EQ(view->split == Split::Train ? "train" : "test", im["split"].get<std::string>());
        EXPECT_FALSE(view->mask_path.empty()) << name;
        const Camera& c = view->camera;
        EXPECT_EQ(c.width, im["width"].get<int>());
        EXPECT_NEAR(c.fx, im["fx"].get<double>(), 1e-6);
        EXPECT_NEAR(c.cy, im["cy"].get<double>(), 1e-6);
        // c2w in meta.json is the inverse of the COLMAP pose.
        const auto& c2w = im["c2w"];
        const Vec3d center = c.center();
        for (int r = 0; r < 3; ++r) {
            EXPECT_NEAR(center[r], c2w[r][3].get<double>(), 1e-6);
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(c.rotation(k, r), c2w[r][k].get<double>(), 1e-9);
        }
        const Image mask = d.load_mask(*view);
        EXPECT_EQ(mask.width, c.width);
    }
}

// Every file an evaluation of data/plaza reads exists here with the same meaning and format.
TEST(SynthDataset, HasPlazaLayoutAndMetaKeys) {
    const std::string root = tiny_dataset();
    const auto meta = synth_test::read_json(root + "/meta.json");
    std::set<std::string> train_conditions, test_conditions, conditions;
    for (const auto& c : meta["conditions"]) {
        conditions.insert(c["id"].get<std::string>());
        EXPECT_TRUE(fs::exists(root + "/" + c["sh"].get<std::string>()));
        EXPECT_TRUE(fs::exists(root + "/" + c["env_exr"].get<std::string>()));
    }
    int with_transients = 0;
    for (const auto& im : meta["images"]) {
        for (const char* key : {"name", "image_id", "split", "condition", "exposure", "fx", "fy", "cx", "cy",
                                "width", "height", "c2w", "has_transients", "n_transients"})
            ASSERT_TRUE(im.contains(key)) << key;
        const std::string name = im["name"], split = im["split"], cond = im["condition"];
        EXPECT_TRUE(conditions.count(cond)) << cond;
        (split == "train" ? train_conditions : test_conditions).insert(cond);
        const double exposure = im["exposure"];
        if (split == "train") {
            EXPECT_GE(exposure, 0.75);
            EXPECT_LE(exposure, 1.35);
        } else {
            EXPECT_EQ(exposure, 1.0);
            EXPECT_FALSE(im["has_transients"].get<bool>());
        }
        with_transients += im["has_transients"].get<bool>();
        const int w = im["width"], h = im["height"];
        const std::pair<const char*, int> files[] = {{"images/", 3},    {"masks/", 1},
                                                     {"gt/albedo/", 3}, {"gt/normal/", 3},
                                                     {"gt/mask/", 1},   {"gt/transient/", 1}};
        for (const auto& [folder, channels] : files) {
            const ImageInfo info = read_image_info(root + "/" + folder + name);
            EXPECT_EQ(info.width, w) << folder << name;
            EXPECT_EQ(info.height, h) << folder << name;
            EXPECT_EQ(info.channels, channels) << folder << name;
        }
        // masks = 255 - gt/transient, and a photo with pedestrians has transient pixels.
        const Image mask = read_image(root + "/masks/" + name),
                    transient = read_image(root + "/gt/transient/" + name);
        float transient_sum = 0;
        for (std::size_t i = 0; i < mask.pixels.size(); ++i) {
            EXPECT_FLOAT_EQ(mask.pixels[i] + transient.pixels[i], 1.0f);
            transient_sum += transient.pixels[i];
        }
        EXPECT_EQ(transient_sum > 0, im["has_transients"].get<bool>()) << name;
    }
    EXPECT_EQ(with_transients, 2);  // round(0.25 * 8)
    for (const std::string& c : test_conditions) EXPECT_EQ(train_conditions.count(c), 0u) << c;
    EXPECT_EQ(test_conditions.size(), 2u);
    // split.csv, as in plaza: a header and `filename;split` per image.
    const std::string split = synth_test::read_bytes(root + "/split.csv");
    EXPECT_EQ(split.rfind("filename;split\ntrain_0000.png;train\n", 0), 0u);
    EXPECT_NE(split.find("test_0001.png;test\n"), std::string::npos);
    EXPECT_TRUE(fs::exists(root + "/README.md"));
}

// The meta.json keys per image are those of the shared plaza dataset (when it is present).
TEST(SynthDataset, ImageKeysMatchSharedPlaza) {
    const std::string plaza = std::string(LUMIGAUSS_SHARED_DIR) + "/data/plaza_mini/meta.json";
    if (!fs::exists(plaza)) GTEST_SKIP() << "no " << plaza;
    const auto ours = synth_test::read_json(tiny_dataset() + "/meta.json");
    const auto theirs = synth_test::read_json(plaza);
    std::set<std::string> ours_keys, their_keys;
    for (const auto& [k, v] : ours["images"][0].items()) ours_keys.insert(k);
    for (const auto& [k, v] : theirs["images"][0].items())
        if (k != "render_seconds") their_keys.insert(k);  // timings would break byte-identical output
    EXPECT_EQ(ours_keys, their_keys);
    for (const char* key : {"id", "split", "sh", "env_exr", "sun_dir_world", "sun_power_rgb",
                            "irradiance_up_numeric", "irradiance_up_sh", "sun_env_pixel_rowcol"})
        EXPECT_TRUE(ours["conditions"][0].contains(key)) << key;
}

// Tracks are consistent with the 2D observations, and every observation's camera ray meets the landmark
// where the point was sampled (the written point carries noise of the documented size).
TEST(SynthDataset, PointsReprojectOntoTheirSurfaces) {
    const std::string root = tiny_dataset();
    const auto meta = synth_test::read_json(root + "/meta.json");
    const synth_test::TrackModel m = synth_test::read_tracks(root + "/sparse/0");
    const Dataset d = load_dataset(root, DatasetOptions{});
    std::map<std::string, const View*> views;
    for (const View& v : d.views) views[v.name] = &v;
    const synth::Landmark landmark = synth::build_landmark(meta["scene"]);
    const double sigma = meta["point_noise_sigma_per_axis"];
    ASSERT_GT(sigma, 0.0);
    ASSERT_GT(m.points.size(), 50u);
    double sq_offset = 0;
    int n_offsets = 0;
    for (const auto& p : m.points) {
        ASSERT_GE(p.track.size(), 2u);
        for (const auto& [image_id, idx] : p.track) {
            const auto& obs = m.observations.at(image_id);
            ASSERT_LT(idx, int(obs.size()));
            ASSERT_EQ(obs[std::size_t(idx)].point_id, p.id);
            const View& v = *views.at(m.image_names.at(image_id));
            ASSERT_EQ(v.split, Split::Train);
            const synth::Ray ray =
                synth::camera_ray(v.camera, obs[std::size_t(idx)].x, obs[std::size_t(idx)].y);
            const auto hit = synth::trace(landmark.world, ray);
            ASSERT_TRUE(hit.has_value());
            const Vec3d surface = ray.origin + hit->hit.t * ray.dir;
            const Vec3d offset = Vec3d{p.x, p.y, p.z} - surface;
            // The observations of one point are projections of one surface point: all rays meet there.
            EXPECT_LT(length(offset), 6 * sigma) << "point " << p.id << " image " << image_id;
            sq_offset += dot(offset, offset), ++n_offsets;
        }
    }
    // RMS offset per axis ~ sigma (the noise), not more.
    EXPECT_NEAR(std::sqrt(sq_offset / (3 * n_offsets)), sigma, 0.35 * sigma);
}

// Without noise the written point is the surface point itself.
TEST(SynthDataset, NoiseFreePointsLieOnTheSurface) {
    TempDir dir("synth_points");
    synth::SynthOptions o = synth_test::tiny_options(dir.str());
    o.point_noise = 0;
    o.point_candidates = 400;
    o.width = 48, o.height = 36;
    synth::generate_synthetic_scene(o);
    const synth_test::TrackModel m = synth_test::read_tracks(dir.sub("sparse/0"));
    const Dataset d = load_dataset(dir.str(), DatasetOptions{});
    const synth::Landmark landmark = synth::build_landmark(o.scene);
    ASSERT_FALSE(m.points.empty());
    for (const auto& p : m.points) {
        EXPECT_LT(p.error, 0.01);
        const auto [image_id, idx] = p.track[0];
        const View* view = nullptr;
        for (const View& v : d.views)
            if (v.name == m.image_names.at(image_id)) view = &v;
        const auto& o2d = m.observations.at(image_id)[std::size_t(idx)];
        const synth::Ray ray = synth::camera_ray(view->camera, o2d.x, o2d.y);
        const auto hit = synth::trace(landmark.world, ray);
        ASSERT_TRUE(hit.has_value());
        const Vec3d surface = ray.origin + hit->hit.t * ray.dir;
        EXPECT_LT(length(Vec3d{p.x, p.y, p.z} - surface), 2e-3 * hit->hit.t) << p.id;
    }
}

}  // namespace
}  // namespace lumigauss
