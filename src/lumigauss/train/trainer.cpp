#include "lumigauss/train/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/image_metrics.h"
#include "lumigauss/io/scene_extent.h"
#include "lumigauss/model/ground_albedo.h"
#include "lumigauss/render/background.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/train/depth_normal.h"
#include "lumigauss/train/empty_space_prune.h"
#include "lumigauss/train/ground_light_prior.h"
#include "lumigauss/train/image_losses.h"
#include "lumigauss/train/physical_losses.h"
#include "lumigauss/train/scale_ratio_penalty.h"
#include "lumigauss/train/sky_hemisphere_prior.h"
#include "lumigauss/train/sky_losses.h"
#include "lumigauss/train/view_shading_backward.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/rng.h"
#include "lumigauss/util/text.h"

namespace lumigauss {
namespace {

// Stream purposes of the training generator.
constexpr std::uint64_t kCameraOrder = 0x63616d6f72646572ULL;  // "camorder"
constexpr std::uint64_t kEnvNoise = 0x656e766e6f697365ULL;     // "envnoise"
constexpr std::uint64_t kDensify = 0x64656e736966ULL;          // "densif"
// config geometric_transfer_every, as fractions of the scene extent: shadow rays start a little off the
// surfel, and parallel surfels this near its plane are layers of the same surface (a trained ground is
// a stack of surfels about a metre deep in a 100 m plaza; bench/RESULTS.md, session 33).
constexpr double kTransferStartFraction = 0.001;
constexpr double kTransferLayerFraction = 0.01;

using Clock = std::chrono::steady_clock;

}  // namespace

ModelLearningRates model_learning_rates(const TrainConfig& c) {
    ModelLearningRates lr;
    lr.position_init = c.lr_position_init;
    lr.position_final = c.lr_position_final;
    lr.position_max_steps = c.lr_position_max_steps;
    lr.transfer = c.lr_transfer;
    lr.opacity = c.lr_opacity;
    lr.scaling = c.lr_scaling;
    lr.rotation = c.lr_rotation;
    lr.albedo = c.lr_albedo;
    return lr;
}

std::vector<AdamGroup> lighting_optimizer(const TrainConfig& c, int num_images) {
    std::vector<AdamGroup> groups;
    for (int g = 0; g < kMlpGroupCount; ++g) {
        const auto group = MlpGroup(g);
        const double lr = group == MlpGroup::kEmbedding ? c.lr_embedding : c.lr_mlp;
        groups.emplace_back(mlp_group_name(group), LightingMlp::group_size(group, num_images), lr,
                            LightingMlp::row_width(group));
    }
    return groups;
}

std::vector<AdamGroup> sky_residual_optimizer(const TrainConfig& c, int num_images) {
    std::vector<AdamGroup> groups;
    for (int i = 0; i < num_images; ++i)
        groups.emplace_back("sky_residual", std::size_t(SkyResiduals::kRowWidth), c.lr_sky_residual,
                            SkyResiduals::kRowWidth);
    return groups;
}

namespace {

// The world's up of the training photos (cameras/up_axis.h); +z when they do not give one.
Vec3d views_up(const std::vector<TrainView>& views) {
    std::vector<Mat3d> rotations;
    for (const TrainView& v : views) rotations.push_back(v.camera.rotation);
    const Vec3d up = camera_up_direction(rotations);
    return length(up) > 0 ? up : Vec3d{0, 0, 1};
}

bool uses_sky_residual(const TrainConfig& c) {
    return c.sky_background && c.sky_residual;
}

// The ground is drawn below the sky's horizon (an object mask's outside is empty space, the ground included).
bool draws_ground_backdrop(const TrainConfig& c) {
    return c.ground_backdrop && c.mask_mode != "object";
}

// Deinterleaves channels [first, first + 3) of an image with `channels` values per pixel.
void extract_rgb(const std::vector<float>& src, int channels, int first, std::vector<float>& dst) {
    const std::size_t pixels = src.size() / std::size_t(channels);
    dst.resize(3 * pixels);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c)
            dst[3 * p + std::size_t(c)] = src[p * std::size_t(channels) + std::size_t(first + c)];
}

void insert_rgb(const std::vector<float>& src, int channels, int first, std::vector<float>& dst) {
    const std::size_t pixels = src.size() / 3;
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c)
            dst[p * std::size_t(channels) + std::size_t(first + c)] = src[3 * p + std::size_t(c)];
}

double masked_psnr(std::span<const float> rendered, std::span<const float> target,
                   std::span<const float> mask) {
    double err = 0, weight = 0;
    for (std::size_t p = 0; p < mask.size(); ++p) {
        for (int c = 0; c < 3; ++c) {
            const double d =
                double(rendered[3 * p + std::size_t(c)]) - double(target[3 * p + std::size_t(c)]);
            err += double(mask[p]) * d * d;
        }
        weight += 3.0 * double(mask[p]);
    }
    // The evaluation's PSNR (io/image_metrics.h: the same epsilon and formula) of the render the losses see,
    // unclamped.
    return psnr_from_mse(weight > 0 ? err / weight : 0.0);
}

bool all_finite(std::span<const float> v) {
    for (float x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

}  // namespace

std::vector<TrainView> load_train_views(const Dataset& dataset) {
    std::vector<TrainView> out;
    for (const View* v : dataset.split(Split::Train)) {
        TrainView t;
        t.name = v->name;
        t.camera = v->camera;
        t.rgb = dataset.load_image(*v);
        t.mask = dataset.load_mask(*v);
        t.sky = dataset.load_sky_mask(*v);
        t.coverage = dataset.load_coverage(*v);
        t.ev100 = v->exif.ev100();
        out.push_back(std::move(t));
    }
    return out;
}

std::vector<float> exif_exposure_factors(const std::vector<TrainView>& views) {
    double sum = 0;
    int known = 0;
    for (const TrainView& v : views)
        if (v.ev100) sum += *v.ev100, ++known;
    std::vector<float> factors(views.size(), 1.0f);
    if (known == 0) return factors;
    const double mean = sum / known;
    for (std::size_t i = 0; i < views.size(); ++i)
        if (views[i].ev100) factors[i] = float(std::exp2(mean - *views[i].ev100));
    return factors;
}

namespace {

// Trainer::exposures of a run: the EXIF factors with config exif_exposure, else 1 for every photo.
std::vector<float> run_exposures(const TrainConfig& config, const std::vector<TrainView>& views) {
    return config.exif_exposure ? exif_exposure_factors(views) : std::vector<float>(views.size(), 1.0f);
}

// `sh` times a photo's exposure (1 changes nothing: x * 1 is exact).
ShCoeffs<float> times_exposure(ShCoeffs<float> sh, float exposure) {
    for (auto& c : sh.c) c = exposure * c;
    return sh;
}

}  // namespace

Stage stage_of(const TrainConfig& config, std::int64_t iteration) {
    if (iteration < config.warmup) return Stage::Unshadowed;
    if (iteration <= config.start_shadowed) return Stage::TransferFitting;
    return Stage::Shadowed;
}

const char* stage_name(Stage stage) {
    switch (stage) {
        case Stage::Unshadowed:
            return "unshadowed";
        case Stage::TransferFitting:
            return "transfer";
        case Stage::Shadowed:
            return "shadowed";
    }
    return "?";
}

NonFiniteError::NonFiniteError(std::int64_t iteration_, std::string term_)
    : std::runtime_error("iteration " + std::to_string(iteration_) + ": " + term_ +
                         " is not finite (NaN or Inf)"),
      iteration(iteration_),
      term(std::move(term_)) {}

// What each photo's losses act on, fixed for the run (from the photo's masks and the config).
struct Trainer::ViewMasks {
    std::vector<float> photometric;  // the photometric loss's mask (the photo's mask as loaded)
    std::vector<float> empty;        // pixels that must stay empty: the eroded sky, or an object's outside
    // The same before the erosion, which keeps the alpha penalty off the edges: a surfel on an edge has
    // under half its weight on either side, and a painter of the sky band at the horizon just over half.
    std::vector<float> empty_unshrunk;
    std::vector<float> sky;          // pixels whose photo shows the sky (eroded sky mask); empty: no sky mask
    std::vector<float> regularizer;  // the normal/distortion losses' mask
    std::vector<Vec3f> unseen_sky;   // the sky hemisphere prior's directions: those the camera does not see
    // The prior's target when the photo has a sky mask (fixed for the run; without one it follows the
    // background-matched pixels of each iteration). Empty: too few sky pixels, no prior.
    std::optional<Vec3f> masked_sky_target;
};

struct Trainer::Scratch {
    ViewNormals normals;
    std::vector<Vec3f> rays;  // world ray of every pixel of the view (sky background)
    SkyPixels sky;            // the sky along every ray: radiance and colour
    std::vector<float> g_sky, g_sky_radiance, matched;  // their gradients; background-explained pixels
    SurfelBatch<float> batch;
    std::unique_ptr<Rasterizer> rasterizer = make_rasterizer(RasterBackend::Cpu);
    SurfelFootprints footprints;  // of the last render, for densification
    RasterImages<float> images;
    RasterImageGrads<float> image_grads;
    SurfelGrads<float> surfel_grads;
    std::vector<float> rendered, grad_rendered, mean2d, damping;
    RasterSettings<float> settings;
};

Trainer::Trainer(std::vector<TrainView> views, const std::vector<Vec3f>& point_xyz,
                 const std::vector<Vec3f>& point_rgb, const TrainConfig& config)
    : views_(std::move(views)), scratch_(std::make_unique<Scratch>()) {
    validate_train_config(config);
    if (views_.empty()) throw Error("training needs at least one training photo; the dataset has none");
    if (point_xyz.empty()) throw Error("training starts from SfM points, and none were given");
    state_.config = config;
    std::vector<View> cams(views_.size());
    for (std::size_t i = 0; i < views_.size(); ++i) cams[i].camera = views_[i].camera;
    state_.scene_extent = camera_extent(cams).radius;
    for (const auto& v : views_) state_.image_names.push_back(v.name);
    const Vec3d up = views_up(views_);
    up_ = up.cast<float>();
    std::vector<Vec3f> xyz = point_xyz, rgb = point_rgb;
    if (config.ground_seeds) {
        std::vector<Vec3d> centres;
        for (const TrainView& v : views_) centres.push_back(v.camera.center());
        ground_ = ground_seeds(point_xyz, point_rgb, centres, up, state_.scene_extent);
        xyz.insert(xyz.end(), ground_.xyz.begin(), ground_.xyz.end());
        rgb.insert(rgb.end(), ground_.rgb.begin(), ground_.rgb.end());
    }
    state_.model = GaussianModel::from_points(xyz, rgb, state_.scene_extent, config.seed,
                                              model_learning_rates(config), config.init_normals_from_points);
    state_.lighting = LightingMlp(int(views_.size()), std::uint32_t(config.seed));
    if (config.lighting_init_radiance > 0) {
        // Every photo's environment starts as a uniform radiance: the DC coefficient of each channel.
        std::vector<float>& bias = state_.lighting.param(MlpGroup::kB3);
        for (int ch = 0; ch < 3; ++ch)
            bias[std::size_t(ch * kShCount)] += float(config.lighting_init_radiance / sh_const::kY00);
    }
    state_.lighting_adam = lighting_optimizer(config, int(views_.size()));
    if (uses_sky_residual(config)) {
        state_.sky_residuals = SkyResiduals(int(views_.size()));
        state_.sky_residual_adam = sky_residual_optimizer(config, int(views_.size()));
    }
    exposure_ = run_exposures(config, views_);
    prepare_view_masks();
}

Trainer::Trainer(std::vector<TrainView> views, TrainState state)
    : views_(std::move(views)), state_(std::move(state)), scratch_(std::make_unique<Scratch>()) {
    validate_train_config(state_.config);
    if (views_.size() != state_.image_names.size())
        throw Error("the saved run was trained on " + std::to_string(state_.image_names.size()) +
                    " photos, the dataset has " + std::to_string(views_.size()) + " training photos");
    for (std::size_t i = 0; i < views_.size(); ++i)
        if (views_[i].name != state_.image_names[i])
            throw Error("the saved run's training photo " + std::to_string(i) + " is '" +
                        state_.image_names[i] + "', the dataset's is '" + views_[i].name + "'");
    // A saved state with NaN/Inf would fail at once or, worse, silently keep the bad surfels: refuse it.
    for (int p = 0; p < kModelParamCount; ++p)
        if (!all_finite(state_.model.param(ModelParam(p))))
            throw Error(std::string("the saved run's surfel parameter '") +
                        GaussianModel::name(ModelParam(p)) + "' holds NaN or Inf values");
    for (int g = 0; g < kMlpGroupCount; ++g)
        if (!all_finite(state_.lighting.param(MlpGroup(g))))
            throw Error(std::string("the saved run's lighting parameter '") + mlp_group_name(MlpGroup(g)) +
                        "' holds NaN or Inf values");
    if (uses_sky_residual(state_.config) && state_.sky_residuals.num_images() != int(views_.size()))
        throw Error("the saved run has sky residuals for " +
                    std::to_string(state_.sky_residuals.num_images()) + " photos, the dataset has " +
                    std::to_string(views_.size()) + " training photos");
    up_ = views_up(views_).cast<float>();
    exposure_ = run_exposures(state_.config, views_);
    prepare_view_masks();
}

ShCoeffs<float> Trainer::environment(int view) const {
    return times_exposure(state_.lighting.env_sh(view), exposure_[std::size_t(view)]);
}

void Trainer::prepare_view_masks() {
    const TrainConfig& c = state_.config;
    const bool object_masks = c.mask_mode == "object";
    masks_.assign(views_.size(), ViewMasks{});
    for (std::size_t v = 0; v < views_.size(); ++v) {
        const TrainView& view = views_[v];
        ViewMasks& m = masks_[v];
        const std::size_t pixels = view.mask.pixels.size();
        m.photometric = view.mask.pixels;
        m.regularizer = view.mask.pixels;
        if (c.lambda_sky_hemisphere > 0)
            m.unseen_sky = directions_out_of_view(upper_hemisphere_directions(up_, kSkyHemisphereDirections),
                                                  view.camera);
        if (!view.sky.pixels.empty() && c.use_sky_masks) {
            m.sky = eroded_mask(view.sky, c.sky_mask_erosion);
            if (c.lambda_sky_hemisphere > 0)
                m.masked_sky_target = mean_sky_radiance(view.rgb.pixels, m.sky, kSkyHemisphereMinPixels);
            if (c.sky_free_regularizers)
                for (std::size_t p = 0; p < pixels; ++p)
                    m.regularizer[p] *= 1.0f - std::min(1.0f, view.sky.pixels[p] * 2.0f);
        }
        if (object_masks) {
            // The outside of the object is empty space: no photometric loss there (the mask), alpha -> 0.
            // Pixels the undistorted photo does not cover are unknown, not empty.
            Image outside = view.mask;
            for (std::size_t p = 0; p < pixels; ++p)
                outside.pixels[p] = (1.0f - outside.pixels[p]) *
                                    (view.coverage.pixels.empty() ? 1.0f : view.coverage.pixels[p]);
            m.empty = eroded_mask(outside, c.sky_mask_erosion);
            m.empty_unshrunk = outside.pixels;
        } else {
            m.empty = m.sky;
            if (!m.sky.empty()) m.empty_unshrunk = view.sky.pixels;
        }
    }
}

SkyHorizon Trainer::sky_horizon() const {
    return sky_horizon(draws_ground_backdrop(state_.config) ? ground_albedo(state_.model, up_) : Vec3f{});
}

SkyHorizon Trainer::sky_horizon(const Vec3f& ground) const {
    const TrainConfig& c = state_.config;
    SkyHorizon horizon{up_, float(c.sky_horizon_start), float(c.sky_horizon_fade)};
    if (draws_ground_backdrop(c)) horizon.ground_albedo = ground;
    return horizon;
}

void Trainer::set_backend(RasterBackend backend) {
    scratch_->rasterizer = make_rasterizer(backend);
}

Trainer::~Trainer() = default;

int Trainer::view_for_iteration(std::int64_t iteration) const {
    // Official: pop a random camera from a list refilled each epoch, i.e. a permutation per epoch.
    const auto n = std::int64_t(views_.size());
    const std::int64_t k = iteration - 1, epoch = k / n, pos = k % n;
    std::vector<int> order(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    Rng rng(hash_keys(state_.config.seed, kCameraOrder, std::uint64_t(epoch)));
    for (std::int64_t i = n - 1; i > 0; --i)
        std::swap(order[std::size_t(i)], order[std::size_t(rng.uniform_int(0, int(i)))]);
    return order[std::size_t(pos)];
}

void Trainer::set_learning_rates(std::int64_t iteration) {
    const TrainConfig& c = state_.config;
    // Official update_lambdas: during (warmup, start_shadowed] the lighting and rotation rates are 0; after
    // it the rotation rate is restored and the lighting rates divided by lr_env_final_ratio.
    const bool frozen = iteration > c.warmup && iteration <= c.start_shadowed;
    const bool late = iteration > c.start_shadowed;
    state_.model.adam(ModelParam::Rotation).set_lr(frozen ? 0.0 : c.lr_rotation);
    // A baked transfer is not learned: its Adam moments from stage 2 must not go on moving it.
    const double transfer_lr = late && c.geometric_transfer_every > 0 ? 0.0 : c.lr_transfer;
    state_.model.adam(ModelParam::TransferPositive).set_lr(transfer_lr);
    state_.model.adam(ModelParam::TransferNegative).set_lr(transfer_lr);
    for (int g = 0; g < kMlpGroupCount; ++g) {
        const double base = MlpGroup(g) == MlpGroup::kEmbedding ? c.lr_embedding : c.lr_mlp;
        state_.lighting_adam[std::size_t(g)].set_lr(frozen ? 0.0 : late ? base / c.lr_env_final_ratio : base);
    }
}

StepReport Trainer::step() {
    const std::int64_t it = state_.iteration + 1;
    const Stage stage = stage_of(state_.config, it);
    StepReport report;
    report.iteration = it;
    report.stage = stage;
    state_.model.zero_grad();
    lighting_grads_.reset(state_.lighting);
    sky_residual_grads_.reset(state_.sky_residuals);
    lighting_has_grad_ = false;
    set_learning_rates(it);

    report.view = view_for_iteration(it);
    last_view_ = report.view;
    if (stage == Stage::Shadowed && bakes_transfer(it)) bake_transfer();
    compute_view_normals(state_.model, views_[std::size_t(report.view)].camera, scratch_->normals,
                         side_rule());
    if (stage != Stage::TransferFitting) render_step(it, stage, report);
    physical_step(it, stage, report);
    check_finite(it, report);
    densify_step(it, stage, report);
    optimizer_step(it, stage);
    report.surfels = state_.model.size();
    state_.iteration = it;
    return report;
}

void Trainer::render_step(std::int64_t it, Stage stage, StepReport& report) {
    const TrainConfig& c = state_.config;
    Scratch& s = *scratch_;
    const TrainView& view = views_[std::size_t(report.view)];
    GaussianModel& model = state_.model;

    auto t0 = Clock::now();
    // A weighted median over every surfel: made once per step for the sky's ground backdrop and the
    // ground-light prior.
    const bool needs_ground = (c.sky_background && draws_ground_backdrop(c)) || c.lambda_ground_light > 0;
    const Vec3f ground = needs_ground ? ground_albedo(model, up_) : Vec3f{};
    const LightingForward<float> env_pass = state_.lighting.forward(report.view);
    // The photo's environment: its exposure (1 unless exif_exposure) x the network's output.
    const float exposure = exposure_[std::size_t(report.view)];
    const ShCoeffs<float> clean = times_exposure(env_pass.sh, exposure);
    // 3.5: one noise draw per iteration, shared by both renders; l_+ sees the clean SH.
    ShCoeffs<float> env = clean;
    Rng noise(hash_keys(c.seed, kEnvNoise, std::uint64_t(it)));
    for (int k = 0; k < kShCount; ++k)
        for (int ch = 0; ch < 3; ++ch) env.c[k][ch] += float(noise.normal() * c.env_noise_sigma);
    const ShadingMode mode = stage == Stage::Shadowed ? ShadingMode::Both : ShadingMode::Unshadowed;
    model.activated(s.batch);
    shade_surfels(model, env, mode, s.normals, s.batch);
    times_.shading += seconds_since(t0);

    t0 = Clock::now();
    s.rasterizer->forward(view.camera, s.batch, s.settings, s.images);
    // The colour sets the losses read: unshadowed RGB alone in stage 1, shadowed and unshadowed in stage 3.
    std::vector<int> colour_sets = {0};
    if (stage != Stage::Unshadowed) colour_sets = {kShadowedOffset, kUnshadowedOffset};
    const bool residual = uses_sky_residual(c);
    Sh4Coeffs<float> sky_residual{};
    if (residual) sky_residual = state_.sky_residuals.get(report.view);
    if (c.sky_background) {
        s.rays = pixel_ray_directions(view.camera);
        sky_pixels(s.rays, env, residual ? &sky_residual : nullptr, s.sky, sky_horizon(ground));
        for (int first : colour_sets) composite_background<float>(s.images, s.sky.colour, first);
    }
    times_.raster_forward += seconds_since(t0);

    t0 = Clock::now();
    const int channels = s.batch.channels;
    const ImageShape shape{view.rgb.width, view.rgb.height, 3};
    std::span<const float> target = view.rgb.pixels, mask = masks_[std::size_t(report.view)].photometric;
    RasterImageGrads<float>& g = s.image_grads;
    // The buffers keep their capacity from iteration to iteration (assign/clear do not free): no allocation
    // in the loop. Maps without a loss this iteration stay empty, so the backward skips them.
    const bool regularize = it > c.start_regularization;
    const ViewMasks& masks = masks_[std::size_t(report.view)];
    const bool empty_pixels = c.lambda_sky_alpha > 0 && !masks.empty.empty();
    const bool match_background = c.sky_background && c.lambda_background_alpha > 0 && masks.sky.empty() &&
                                  c.mask_mode != "object" && it >= c.background_alpha_from;
    const bool alpha_loss = regularize || c.sky_background || empty_pixels || match_background;
    const std::size_t pixels = shape.pixels();
    g.width = shape.width, g.height = shape.height, g.channels = channels;
    g.color.assign(s.images.color.size(), 0.0f);
    const auto reset = [&](std::vector<float>& map, std::size_t size, bool used) {
        if (used)
            map.assign(size, 0.0f);
        else
            map.clear();
    };
    reset(g.alpha, pixels, alpha_loss), reset(g.depth, pixels, regularize);
    reset(g.distortion, pixels, regularize), reset(g.normal, 3 * pixels, regularize);
    g.median_depth.clear();
    const auto photometric = [&](int first, double weight, double& l1, double& dssim) -> double {
        extract_rgb(s.images.color, channels, first, s.rendered);
        s.grad_rendered.assign(s.rendered.size(), 0.0f);
        l1 = masked_l1_loss<float>(shape, s.rendered, target, mask, float(weight * (1 - c.lambda_dssim)),
                                   s.grad_rendered);
        dssim = masked_dssim_loss<float>(shape, s.rendered, target, mask, float(weight * c.lambda_dssim),
                                         s.grad_rendered);
        insert_rgb(s.grad_rendered, channels, first, g.color);
        return masked_psnr(s.rendered, target, mask);
    };
    double image_total = 0;
    if (stage == Stage::Unshadowed) {
        report.psnr = photometric(0, 1.0, report.l1_unshadowed, report.dssim_unshadowed);
        image_total = (1 - c.lambda_dssim) * report.l1_unshadowed + c.lambda_dssim * report.dssim_unshadowed;
    } else {
        photometric(kUnshadowedOffset, c.lambda_unshadowed_stage3, report.l1_unshadowed,
                    report.dssim_unshadowed);
        report.psnr = photometric(kShadowedOffset, 1.0, report.l1_shadowed, report.dssim_shadowed);
        image_total = (1 - c.lambda_dssim) * report.l1_shadowed + c.lambda_dssim * report.dssim_shadowed +
                      c.lambda_unshadowed_stage3 * ((1 - c.lambda_dssim) * report.l1_unshadowed +
                                                    c.lambda_dssim * report.dssim_unshadowed);
    }
    report.total += image_total;
    if (regularize) {
        const std::span<const float> reg_mask = masks.regularizer;
        report.normal =
            normal_consistency_loss<float>(view.camera, s.images, reg_mask, float(c.lambda_normal), &g);
        report.distortion = distortion_loss<float>(s.images, reg_mask, float(c.lambda_distortion), &g);
        report.total += c.lambda_normal * report.normal + c.lambda_distortion * report.distortion;
    }
    if (empty_pixels) {
        report.sky_alpha = alpha_penalty(s.images.alpha, masks.empty, c.lambda_sky_alpha, g.alpha);
        report.total += c.lambda_sky_alpha * report.sky_alpha;
    }
    if (match_background) {
        s.matched = background_match_mask(target, s.sky.colour, mask, s.rays, up_, shape.width, shape.height,
                                          c.background_match_tolerance);
        report.background_alpha =
            alpha_penalty(s.images.alpha, s.matched, c.lambda_background_alpha, g.alpha);
        report.total += c.lambda_background_alpha * report.background_alpha;
    }
    if (c.sky_background) {
        s.g_sky.assign(s.sky.colour.size(), 0.0f);
        s.g_sky_radiance.clear();
        if (c.lambda_sky_colour > 0 && !masks.sky.empty()) {
            s.g_sky_radiance.assign(s.sky.radiance.size(), 0.0f);
            report.sky_colour = sky_colour_loss(s.sky.colour, s.sky.radiance, target, masks.sky,
                                                c.lambda_sky_colour, s.g_sky, s.g_sky_radiance);
            report.total += c.lambda_sky_colour * report.sky_colour;
        }
        for (int first : colour_sets)
            composite_background_backward<float>(s.images, s.sky.colour, first, g, s.g_sky);
    }
    ShCoeffs<float> g_env{};
    if (c.sky_background) {
        const SkyGrads sky_grads = sky_pixels_backward(s.rays, s.sky, s.g_sky, s.g_sky_radiance, residual);
        if (c.sky_pins_light) g_env = sky_grads.env;
        if (residual) {
            // L2 penalty: the residual only takes what the lighting cannot hold.
            Sh4Coeffs<float> g_res = sky_grads.residual;
            double penalty = 0;
            for (int k = 0; k < kSh4Count; ++k) {
                penalty += double(dot(sky_residual.c[k], sky_residual.c[k]));
                g_res.c[k] += float(2 * c.lambda_sky_residual) * sky_residual.c[k];
            }
            report.sky_residual = penalty;
            report.total += c.lambda_sky_residual * penalty;
            if (c.lambda_sky_hemisphere > 0) {
                // The sky the photo shows: its sky mask, else what the sky background already explains.
                std::optional<Vec3f> sky_target = masks.masked_sky_target;
                if (masks.sky.empty() && match_background)
                    sky_target = mean_sky_radiance(target, s.matched, kSkyHemisphereMinPixels);
                if (sky_target) {
                    report.sky_hemisphere = sky_hemisphere_prior(masks.unseen_sky, clean, sky_residual,
                                                                 *sky_target, c.lambda_sky_hemisphere, g_res);
                    report.total += c.lambda_sky_hemisphere * report.sky_hemisphere;
                }
            }
            sky_residual_grads_.add(report.view, g_res);
        }
    }
    report.env = env_nonnegativity_loss(clean, c.env_samples, c.seed, it, c.lambda_env, g_env);
    report.total += c.lambda_env * report.env;
    if (c.lambda_ground_light > 0) {
        const Vec3d reflectance = ground_reflectance(ground, c.ground_light_albedo);
        report.ground_light = ground_light_prior(clean, up_, reflectance, c.lambda_ground_light, g_env);
        report.total += c.lambda_ground_light * report.ground_light;
    }
    times_.losses += seconds_since(t0);

    t0 = Clock::now();
    s.rasterizer->backward(s.batch, g, s.surfel_grads);
    const SurfelGrads<float>& sg = s.surfel_grads;
    times_.raster_backward += seconds_since(t0);

    t0 = Clock::now();
    if (c.lambda_opacity > 0) {
        // 3DGS-MCMC: mean opacity, so that a surfel no photo needs fades and is pruned.
        double sum = 0;
        for (float o : s.batch.opacities) sum += o;
        const std::size_t n = s.batch.size();
        report.opacity = n > 0 ? sum / double(n) : 0.0;
        report.total += c.lambda_opacity * report.opacity;
        const float g_each = n > 0 ? float(c.lambda_opacity / double(n)) : 0.0f;
        for (float& v : s.surfel_grads.opacities) v += g_each;
    }
    if (c.lambda_scale_ratio > 0) {
        report.scale_ratio = scale_ratio_penalty(s.batch.scales, c.max_scale_ratio, c.lambda_scale_ratio,
                                                 s.surfel_grads.scales);
        report.total += c.lambda_scale_ratio * report.scale_ratio;
    }
    model.accumulate_grads_from_activated(sg);
    const ShCoeffs<float> g_shading = shade_surfels_backward(model, env, mode, s.normals, sg.colors);
    for (int k = 0; k < kShCount; ++k) g_env.c[k] = g_env.c[k] + g_shading.c[k];
    g_env = times_exposure(g_env, exposure);  // d env / d output = exposure
    lighting_grads_.backward(state_.lighting, env_pass, g_env);
    lighting_has_grad_ = true;
    // Densification statistics come from this render's screen-space gradient (2DGS: radii > 0 visible).
    if (it < c.densify_until) {
        s.rasterizer->footprints(s.footprints);
        s.mean2d = sg.mean2d;
    }
    times_.shading_backward += seconds_since(t0);
}

bool Trainer::bakes_transfer(std::int64_t it) const {
    const TrainConfig& c = state_.config;
    if (c.geometric_transfer_every <= 0) return false;
    const std::int64_t since = it - (c.start_shadowed + 1);
    return since >= 0 && (since % c.geometric_transfer_every == 0 || it == c.iterations);
}

VisibilityTransferOptions Trainer::geometric_transfer_options() const {
    VisibilityTransferOptions options;
    options.start_distance = kTransferStartFraction * state_.scene_extent;
    options.layer_thickness = kTransferLayerFraction * state_.scene_extent;
    options.bounce = state_.config.shadow_bounce;
    return options;
}

void Trainer::bake_transfer() {
    const auto t0 = Clock::now();
    bake_visibility_transfer(state_.model, geometric_transfer_options());
    times_.physical += seconds_since(t0);
}

void Trainer::physical_step(std::int64_t it, Stage stage, StepReport& report) {
    if (stage == Stage::Unshadowed) return;  // stage 1: the transfer gets no gradient (5)
    const TrainConfig& c = state_.config;
    if (stage == Stage::Shadowed && c.geometric_transfer_every > 0) return;  // baked, not learned
    const auto t0 = Clock::now();
    TransferLossWeights<double> w;
    w.range01 = c.lambda_range01;
    // Official update_lambdas: the stage-3 weight is the stage-2 weight times
    // consistency_loss_lambda_final_ratio.
    w.consistency = c.lambda_consistency * (stage == Stage::Shadowed ? c.consistency_final_ratio : 1.0);
    w.shadow = stage == Stage::Shadowed ? c.lambda_shadow : 0.0;
    const TransferLossResult r =
        model_transfer_losses(state_.model, scratch_->normals, c.transfer_samples, c.seed, it, w, true);
    report.range01 = r.losses.range01;
    report.consistency = r.losses.consistency;
    report.shadow = r.losses.shadow;
    report.total += r.weighted;
    times_.physical += seconds_since(t0);
}

void Trainer::check_finite(std::int64_t it, const StepReport& r) const {
    const std::pair<const char*, double> terms[] = {{"loss l1 (shadowed)", r.l1_shadowed},
                                                    {"loss D-SSIM (shadowed)", r.dssim_shadowed},
                                                    {"loss l1 (unshadowed)", r.l1_unshadowed},
                                                    {"loss D-SSIM (unshadowed)", r.dssim_unshadowed},
                                                    {"loss l_[0,1]", r.range01},
                                                    {"loss l_consistency", r.consistency},
                                                    {"loss l_shadow", r.shadow},
                                                    {"loss l_+ (environment)", r.env},
                                                    {"loss normal consistency", r.normal},
                                                    {"loss distortion", r.distortion},
                                                    {"loss sky alpha", r.sky_alpha},
                                                    {"loss sky colour", r.sky_colour},
                                                    {"loss background alpha", r.background_alpha},
                                                    {"loss opacity", r.opacity},
                                                    {"loss scale ratio", r.scale_ratio},
                                                    {"loss sky residual", r.sky_residual},
                                                    {"loss sky hemisphere", r.sky_hemisphere}};
    for (const auto& [name, value] : terms)
        if (!std::isfinite(value)) throw NonFiniteError(it, name);
    for (int p = 0; p < kModelParamCount; ++p)
        if (state_.model.has_grad(ModelParam(p)) && !all_finite(state_.model.grad(ModelParam(p))))
            throw NonFiniteError(it, std::string("gradient of ") + GaussianModel::name(ModelParam(p)));
    for (int g = 0; g < kMlpGroupCount; ++g)
        if (!all_finite(lighting_grads_[MlpGroup(g)]))
            throw NonFiniteError(it, std::string("gradient of lighting ") + mlp_group_name(MlpGroup(g)));
}

void Trainer::post_densification_prune(std::int64_t it, StepReport& report) {
    const TrainConfig& c = state_.config;
    GaussianModel& model = state_.model;
    // Beyond the paper: the prune goes on (nothing else removes a surfel once densification ends).
    const bool prune = c.prune_until_end && it % c.densify_interval == 0 && it < c.iterations;
    // The sweep over every photo costs about as many renders as there are photos: once per opacity-reset
    // rhythm, and at the end so that the saved model holds no painter (and, with min_contribution_pixels, no
    // surfel that adds next to nothing to the photos).
    const bool sweep =
        (c.empty_space_prune_share > 0 && it % c.opacity_reset_interval == 0) ||
        ((c.empty_space_prune_share > 0 || c.min_contribution_pixels > 0 || c.min_ground_views > 0) &&
         it == c.iterations);
    if (!prune && !sweep) return;
    const auto t0 = Clock::now();
    if (prune) {
        // The last opacity reset left every opacity at 0.01: the opacity rule waits half a reset interval
        // for the surfels that matter to recover (densification's own prune waits a whole interval).
        const std::int64_t last_reset =
            ((c.densify_until - 1) / c.opacity_reset_interval) * c.opacity_reset_interval;
        const bool opacity_rule = it - last_reset >= c.opacity_reset_interval / 2;
        report.densified.pruned = model.prune(opacity_rule ? c.min_opacity : 0.0,
                                              DensifyOptions{}.world_size_fraction * state_.scene_extent);
        report.prune_ran = true;
    }
    if (sweep) {
        sweep_and_prune(it == c.iterations, report);
        report.empty_space_swept = true;
    }
    model.zero_grad();
    times_.densify += seconds_since(t0);
}

std::vector<float> Trainer::empty_pixels(int v, const SkyHorizon& horizon) {
    const TrainConfig& c = state_.config;
    const ViewMasks& masks = masks_[std::size_t(v)];
    if (!masks.empty_unshrunk.empty()) return masks.empty_unshrunk;
    const bool match_background =
        c.sky_background && c.lambda_background_alpha > 0 && masks.sky.empty() && c.mask_mode != "object";
    if (!match_background) return {};
    const TrainView& view = views_[std::size_t(v)];
    Scratch& s = *scratch_;
    const bool residual = uses_sky_residual(c);
    Sh4Coeffs<float> sky_residual{};
    if (residual) sky_residual = state_.sky_residuals.get(v);
    s.rays = pixel_ray_directions(view.camera);
    sky_pixels(s.rays, environment(v), residual ? &sky_residual : nullptr, s.sky, horizon);
    return background_match_mask(view.rgb.pixels, s.sky.colour, masks.photometric, s.rays, up_,
                                 view.rgb.width, view.rgb.height, c.background_match_tolerance);
}

double Trainer::lowest_camera_height() const {
    double lowest = std::numeric_limits<double>::infinity();
    for (const TrainView& v : views_) lowest = std::min(lowest, dot(v.camera.center(), up_.cast<double>()));
    return lowest;
}

void Trainer::sweep_and_prune(bool last, StepReport& report) {
    GaussianModel& model = state_.model;
    EmptySpaceWeights weights;
    weights.reset(model.size());
    SurfelBatch<float> geometry;
    std::vector<float> constrained;
    bool any_empty = false;
    model.activated(geometry);
    const SkyHorizon horizon = sky_horizon();  // once: its ground albedo is a pass over every surfel
    for (int v = 0; v < int(views_.size()); ++v) {
        const std::vector<float> empty = empty_pixels(v, horizon);
        any_empty = any_empty || !empty.empty();
        // The pixels the photo constrains: its photometric mask, and the ones that must stay empty (an
        // object mask's outside is outside the photometric mask).
        constrained = masks_[std::size_t(v)].photometric;
        for (std::size_t p = 0; p < empty.size(); ++p) constrained[p] = std::max(constrained[p], empty[p]);
        add_empty_space_weights(*scratch_->rasterizer, views_[std::size_t(v)].camera, geometry, constrained,
                                empty, weights);
    }
    const TrainConfig& c = state_.config;
    std::size_t painters = 0;
    std::vector<std::uint8_t> keep(model.size(), 1);
    if (any_empty && c.empty_space_prune_share > 0)
        keep = keep_outside_empty_space(weights, c.empty_space_prune_share, painters);
    // At the end only: a pass over the finished model (plaza, fast: 13 % fewer surfels, renders 19 % faster,
    // test and training views within 0.03 dB). At every sweep, the model ended 19 % smaller, 0.07 dB lower.
    const std::size_t low = last && c.min_contribution_pixels > 0
                                ? remove_low_contribution(weights, c.min_contribution_pixels, keep)
                                : 0;
    // At the end only, as the low-contribution rule: removed during training (plaza, fast: at every sweep
    // from the end of densification on), the surfels left grew into the same ground and streaked it again.
    const std::size_t ground =
        last && c.min_ground_views > 0
            ? remove_weakly_seen_ground(weights, model.param(ModelParam::Xyz), up_, lowest_camera_height(),
                                        c.min_ground_views, keep)
            : 0;
    if (painters + low + ground > 0) model.keep_rows(keep);
    report.empty_space_pruned = painters, report.low_contribution_pruned = low;
    report.weakly_seen_ground_pruned = ground;
}

void Trainer::densify_step(std::int64_t it, Stage stage, StepReport& report) {
    const TrainConfig& c = state_.config;
    GaussianModel& model = state_.model;
    // Official: only while it < densify_until and outside stage 2.
    if (stage == Stage::TransferFitting) return;
    if (it >= c.densify_until) {
        post_densification_prune(it, report);
        return;
    }
    const auto t0 = Clock::now();
    const TrainView& view = views_[std::size_t(report.view)];
    Scratch& s = *scratch_;
    s.damping.clear();
    if (c.densify_near_fraction > 0) {
        // Pixel-GS: a surfel near the camera covers many pixels, and its summed screen gradient would split
        // it again and again; (depth / near)^2 undoes the growth of its footprint with nearness.
        const double near = c.densify_near_fraction * state_.scene_extent;
        s.damping.assign(model.size(), 1.0f);
        for (std::size_t i = 0; i < model.size(); ++i)
            if (s.footprints.visible[i]) {
                const double r = double(s.footprints.depth[i]) / near;
                s.damping[i] = float(std::min(1.0, r * r));
            }
    }
    model.add_densification_stats(s.mean2d, s.footprints.visible, s.footprints.radius, view.camera.width,
                                  view.camera.height, s.damping);
    if (it > c.densify_from && it % c.densify_interval == 0) {
        const double max_screen = it > c.opacity_reset_interval ? c.max_screen_size : 0.0;
        DensifyOptions opt;
        opt.percent_dense = c.percent_dense;
        opt.faithful_radii_reset = c.faithful_radii_reset;
        report.densified =
            model.densify_and_prune(c.densify_grad_threshold, c.min_opacity, state_.scene_extent, max_screen,
                                    hash_keys(c.seed, kDensify, std::uint64_t(it)), opt);
        report.densify_ran = true;
        // torch: the replaced parameter tensors have no gradient, so Adam skips them this iteration.
        model.zero_grad();
    }
    if (it % c.opacity_reset_interval == 0) {
        model.reset_opacity(float(c.opacity_reset_value));
        model.drop_grad(ModelParam::Opacity);
        report.opacity_reset = true;
    }
    times_.densify += seconds_since(t0);
}

void Trainer::optimizer_step(std::int64_t it, Stage) {
    if (it >= state_.config.iterations) return;  // official: no step on the last iteration
    const auto t0 = Clock::now();
    state_.model.step(it);
    if (lighting_has_grad_) {
        for (int g = 0; g < kMlpGroupCount; ++g)
            state_.lighting_adam[std::size_t(g)].step(state_.lighting.param(MlpGroup(g)),
                                                      lighting_grads_[MlpGroup(g)]);
        if (!state_.sky_residuals.empty()) {
            const std::size_t row = std::size_t(last_view_) * SkyResiduals::kRowWidth;
            state_.sky_residual_adam[std::size_t(last_view_)].step(
                std::span<float>(state_.sky_residuals.params()).subspan(row, SkyResiduals::kRowWidth),
                std::span<const float>(sky_residual_grads_.values()).subspan(row, SkyResiduals::kRowWidth));
        }
    }
    times_.optimizer += seconds_since(t0);
}

}  // namespace lumigauss
