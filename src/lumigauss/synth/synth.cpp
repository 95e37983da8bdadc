// Orchestration of `lumigauss synth`: plan the photos (viewpoint, lighting, exposure, pedestrians), render
// them, then write the point cloud, the COLMAP model and the ground truth.
#include "lumigauss/synth/synth.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "lumigauss/synth/camera_paths.h"
#include "lumigauss/synth/colmap_with_tracks.h"
#include "lumigauss/synth/dataset_writer.h"
#include "lumigauss/synth/gt_surfels.h"
#include "lumigauss/synth/pedestrians.h"
#include "lumigauss/synth/rng.h"
#include "lumigauss/util/error.h"

namespace lumigauss::synth {

namespace {

void validate(const SynthOptions& o) {
    auto require = [](bool ok, const std::string& what) {
        if (!ok) throw Error("synth: " + what);
    };
    require(o.width >= 8 && o.height >= 8 && o.width <= 8192 && o.height <= 8192,
            "image size must be between 8 and 8192 pixels per side");
    require(o.n_train >= 2, "need at least 2 training photos (points must be seen twice)");
    require(o.n_test >= 0 && o.n_train + o.n_test <= 9999, "photo counts must be in 0..9999 in total");
    require(o.transient_fraction >= 0 && o.transient_fraction <= 1,
            "--transients must be a fraction in [0, 1]");
    require(o.samples_per_side >= 1 && o.samples_per_side <= 16, "samples per side must be in 1..16");
    require(o.point_candidates >= 0, "point candidates must be >= 0");
    require(o.point_noise >= 0, "point noise must be >= 0");
    require(o.gt_surfels >= 0, "ground-truth surfel count must be >= 0");
}

// Conditions: about one per three photos, at least two per split (when there are two photos).
int condition_count(int photos) {
    return std::min(photos, std::max(2, (photos + 2) / 3));
}

// Fisher-Yates with our own generator (std::shuffle's algorithm is unspecified).
void shuffle(std::vector<int>& v, Rng& rng) {
    for (int i = int(v.size()) - 1; i > 0; --i)
        std::swap(v[std::size_t(i)], v[std::size_t(rng.uniform_int(0, i))]);
}

// Every condition of a split used about equally often, in a random order.
std::vector<int> assign_conditions(int photos, int first, int count, Rng& rng) {
    std::vector<int> a(static_cast<std::size_t>(photos));
    for (int i = 0; i < photos; ++i) a[std::size_t(i)] = first + i % count;
    shuffle(a, rng);
    return a;
}

std::string photo_name(bool train, int index) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s_%04d.png", train ? "train" : "test", index);
    return buf;
}

std::vector<Photo> plan_photos(const SynthOptions& o, const Landmark& landmark, int n_train_cond,
                               int n_test_cond) {
    Rng assign_train(o.seed, Stream::kAssignment, 0), assign_test(o.seed, Stream::kAssignment, 1);
    const auto train_cond = assign_conditions(o.n_train, 0, n_train_cond, assign_train);
    const auto test_cond = assign_conditions(o.n_test, n_train_cond, std::max(1, n_test_cond), assign_test);
    std::vector<Photo> photos;
    for (int i = 0; i < o.n_train + o.n_test; ++i) {
        const bool train = i < o.n_train;
        Photo p;
        p.train = train;
        p.name = photo_name(train, train ? i : i - o.n_train);
        p.image_id = i + 1;
        p.condition = train ? train_cond[std::size_t(i)] : test_cond[std::size_t(i - o.n_train)];
        Rng exposure(o.seed, Stream::kExposure, std::uint64_t(i));
        p.exposure = train ? exposure.uniform(0.75, 1.35) : 1.0;
        p.camera = make_tourist_camera(landmark, o.width, o.height, o.seed, i);
        photos.push_back(p);
    }
    return photos;
}

// Which training photos get pedestrians: exactly round(fraction * n_train) of them, chosen at random.
std::vector<bool> choose_transient_photos(const SynthOptions& o) {
    std::vector<int> order(std::size_t(o.n_train));
    std::iota(order.begin(), order.end(), 0);
    Rng rng(o.seed, Stream::kAssignment, 2);
    shuffle(order, rng);
    const int count = int(std::lround(o.transient_fraction * o.n_train));
    std::vector<bool> chosen(std::size_t(o.n_train), false);
    for (int k = 0; k < count; ++k) chosen[std::size_t(order[std::size_t(k)])] = true;
    return chosen;
}

double farthest_camera(const std::vector<Photo>& photos, const Landmark& l) {
    const Vec3d c = 0.5 * (l.bbox_lo + l.bbox_hi);
    double d = 0;
    for (const Photo& p : photos) {
        const Vec3d e = p.camera.center();
        d = std::max(d, std::hypot(e.x - c.x, e.y - c.y));
    }
    return d;
}

// What the point sampler needs of the training photos: each one's world (with its pedestrians) and pixels.
struct TrainingPhotos {
    std::vector<World> worlds;
    std::vector<std::vector<std::uint8_t>> rgb;
};

// Renders every photo and writes its images; adds the pedestrians (recording how many) as it goes.
TrainingPhotos render_photos(const SynthOptions& o, const Landmark& landmark,
                             const std::vector<LightCondition>& conditions, std::vector<Photo>& photos) {
    const std::vector<bool> with_pedestrians = choose_transient_photos(o);
    TrainingPhotos training;
    for (Photo& p : photos) {
        World world = landmark.world;
        if (p.train && with_pedestrians[std::size_t(p.image_id - 1)])
            p.n_transients = add_pedestrians(world, landmark, p.camera, o.seed, p.image_id - 1);
        const LightCondition& light = conditions[std::size_t(p.condition)];
        const ViewBuffers buffers =
            render_view(world, light, p.camera, {o.samples_per_side, o.seed, p.image_id});
        auto rgb8 = write_photo_files(o.output_dir, p, buffers, o.object_masks);
        if (p.train) training.worlds.push_back(std::move(world)), training.rgb.push_back(std::move(rgb8));
        if (o.verbose) std::printf("synth: %s (%s)\n", p.name.c_str(), light.id.c_str());
    }
    return training;
}

// Samples the points3D and writes sparse/0; returns the number of points.
int write_sparse_model(const SynthOptions& o, const Landmark& landmark, const std::vector<Photo>& photos,
                       const TrainingPhotos& training, double noise_sigma) {
    std::vector<TrainingView> views;
    std::vector<ColmapView> colmap_views;
    for (const Photo& p : photos) {
        const int t = p.train ? int(views.size()) : -1;
        if (p.train)
            views.push_back({&training.worlds[std::size_t(t)], &p.camera, &training.rgb[std::size_t(t)]});
        colmap_views.push_back({p.image_id, p.name, p.camera, t});
    }
    SfmSamplingOptions sampling;
    sampling.candidates = o.point_candidates;
    sampling.noise_sigma = noise_sigma;
    sampling.ground_radius = 1.3 * farthest_camera(photos, landmark);
    sampling.seed = o.seed;
    const std::vector<SfmPoint> points = sample_sfm_points(landmark, views, sampling);
    write_colmap_text(o.output_dir + "/sparse/0", colmap_model_with_tracks(colmap_views, points));
    return int(points.size());
}

// The static scene as ground-truth surfels, fitted to what the photos see; writes gt/surfels.ply.
GtSurfels write_gt_surfels(const SynthOptions& o, const Landmark& landmark,
                           const std::vector<Photo>& photos) {
    std::vector<Camera> cameras;
    for (const Photo& p : photos) cameras.push_back(p.camera);
    GtSurfels gt = make_gt_surfels(landmark, cameras, {o.gt_surfels});
    if (o.gt_surfels > 0) save_2dgs_ply(o.output_dir + "/gt/surfels.ply", gt.model);
    return gt;
}

}  // namespace

SynthOptions synth_preset(const std::string& name) {
    SynthOptions o;
    if (name == "tiny") {
        o.width = 64, o.height = 48, o.n_train = 8, o.n_test = 2, o.point_candidates = 1500;
        o.gt_surfels = 12000;
        o.transient_fraction = 0.25;
    } else if (name == "demo") {
        o.width = 160, o.height = 120, o.n_train = 40, o.n_test = 6, o.point_candidates = 8000;
    } else if (name == "bench") {
        o.width = 320, o.height = 240, o.n_train = 60, o.n_test = 12, o.point_candidates = 30000;
        o.gt_surfels = 200000;
    } else {
        throw Error("synth: unknown preset '" + name + "' (choose tiny, demo or bench)");
    }
    return o;
}

SynthSummary generate_synthetic_scene(const SynthOptions& o) {
    const auto start = std::chrono::steady_clock::now();
    validate(o);
    const Landmark landmark = build_landmark(o.scene);
    const int n_train_cond = condition_count(o.n_train), n_test_cond = condition_count(o.n_test);
    const std::vector<LightCondition> conditions = make_conditions(n_train_cond, n_test_cond, o.seed);
    std::vector<Photo> photos = plan_photos(o, landmark, n_train_cond, n_test_cond);
    prepare_output_dir(o);

    const TrainingPhotos training = render_photos(o, landmark, conditions, photos);
    for (const LightCondition& c : conditions) write_environment(o.output_dir, c);
    const double diag = length(landmark.bbox_hi - landmark.bbox_lo);
    const double noise_sigma = o.point_noise * diag / std::sqrt(3.0);  // RMS length = point_noise * diag
    const int n_points = write_sparse_model(o, landmark, photos, training, noise_sigma);
    const GtSurfels gt = write_gt_surfels(o, landmark, photos);
    write_split_csv(o.output_dir, photos);
    const MetaInputs meta{&o, &landmark, &photos, &conditions, n_points, noise_sigma, diag, &gt};
    write_meta_json(o.output_dir, meta);
    write_readme(o.output_dir, meta);

    SynthSummary summary;
    summary.n_train = o.n_train, summary.n_test = o.n_test;
    summary.n_conditions = int(conditions.size());
    summary.n_points = n_points;
    summary.n_gt_surfels = int(gt.model.size());
    for (const Photo& p : photos) summary.n_with_transients += p.n_transients > 0;
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return summary;
}

}  // namespace lumigauss::synth
