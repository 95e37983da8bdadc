#pragma once
// One LumiGauss training run: the surfel model, the lighting model (per-photo embedding -> MLP -> SH), their
// optimizers, and the iteration loop of the official train.py with its three stages
// (research/lumigauss_official.md 3-5; the schedule is described in train_config.h).
//
// Everything random is drawn from counter-based streams keyed by (seed, purpose, iteration, ...): the
// camera order (a fresh permutation per epoch), the SH noise, the Monte Carlo directions and the split
// samples. A run is therefore a pure function of its config and its state at an iteration, which is what
// makes `--resume` exact: a checkpoint holds the state, never a generator.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/model/sky_residual.h"
#include "lumigauss/model/view_shading.h"
#include "lumigauss/model/visibility_transfer.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/train/adam.h"
#include "lumigauss/train/gaussian_model.h"
#include "lumigauss/train/ground_seeds.h"
#include "lumigauss/train/lighting_mlp_gradients.h"
#include "lumigauss/train/sky_losses.h"
#include "lumigauss/train/train_config.h"

namespace lumigauss {

// A training photo in memory: RGB in [0, 1], its mask (one value per pixel; all ones without a mask file)
// and its sky mask (one value per pixel, 1 = sky; empty without a sky mask file).
struct TrainView {
    std::string name;
    Camera camera;
    Image rgb;
    Image mask;
    Image sky;
    // Where the photo holds the pixel's ray after undistortion (Dataset::load_coverage); empty = everywhere.
    Image coverage;
    std::optional<double> ev100;  // the photo's EXIF exposure value (io/photo_exif.h), when it has one
};

// The lighting's fixed per-photo factors of config exif_exposure: 2^(mean EV100 - EV100_i) over the photos
// that have one (the mean exposure is 1), 1 for the others; all 1 when none has one.
std::vector<float> exif_exposure_factors(const std::vector<TrainView>& views);

// The training photos of a dataset (its train split), in dataset (name) order; the position in this list
// is the photo's row in the embedding table.
std::vector<TrainView> load_train_views(const Dataset& dataset);

enum class Stage { Unshadowed = 1, TransferFitting = 2, Shadowed = 3 };
Stage stage_of(const TrainConfig& config, std::int64_t iteration);
const char* stage_name(Stage stage);

// Every term of one iteration, unweighted (0 when not computed), plus the weighted total.
struct StepReport {
    std::int64_t iteration = 0;
    Stage stage = Stage::Unshadowed;
    int view = -1;  // index into the training views: rendered, or (stage 2) whose camera picks the normals
    double total = 0;
    double l1_shadowed = 0, dssim_shadowed = 0;
    double l1_unshadowed = 0, dssim_unshadowed = 0;
    double range01 = 0, consistency = 0, shadow = 0;
    double env = 0, ground_light = 0, normal = 0, distortion = 0;
    double sky_alpha = 0, sky_colour = 0, background_alpha = 0, opacity = 0, sky_residual = 0,
           sky_hemisphere = 0, scale_ratio = 0;
    double psnr = 0;  // masked PSNR of the stage's main render (shadowed in stage 3), 0 in stage 2
    std::size_t surfels = 0;
    DensifyReport densified{};
    bool densify_ran = false, opacity_reset = false;
    bool prune_ran = false;  // the prune alone, after densification (prune_until_end)
    // Surfels removed for painting empty space (config empty_space_prune_share, train/empty_space_prune.h)
    // for adding too little to the photos (min_contribution_pixels), and for lying low where too few photos
    // see them (min_ground_views); the sweep over the photos ran this iteration when empty_space_swept.
    std::size_t empty_space_pruned = 0, low_contribution_pruned = 0, weakly_seen_ground_pruned = 0;
    bool empty_space_swept = false;
};

// The state that fully determines the rest of a run (what a checkpoint stores).
struct TrainState {
    TrainConfig config;
    std::int64_t iteration = 0;  // iterations completed
    double scene_extent = 1;     // cameras_extent (xyz learning rate and densification scale)
    std::vector<std::string> image_names;
    GaussianModel model;
    LightingMlp lighting;
    std::vector<AdamGroup> lighting_adam;  // one per MlpGroup
    SkyResiduals sky_residuals;            // empty unless config.sky_background && config.sky_residual
    // One optimizer per photo: a photo's residual is stepped only when the photo is drawn, so that its
    // moments do not keep moving it on the other photos' iterations (a dense Adam did, by ~30 steps per
    // visit).
    std::vector<AdamGroup> sky_residual_adam;
};

// The model's learning rates and the lighting model's optimizer (one Adam group per MlpGroup) of a config.
ModelLearningRates model_learning_rates(const TrainConfig& config);
std::vector<AdamGroup> lighting_optimizer(const TrainConfig& config, int num_images);
std::vector<AdamGroup> sky_residual_optimizer(const TrainConfig& config, int num_images);

class Trainer {
  public:
    // A new run: surfels from the dataset's SfM points, lighting model from the config's seed. Throws Error
    // if the dataset has no SfM points or no training photos.
    Trainer(std::vector<TrainView> views, const std::vector<Vec3f>& point_xyz,
            const std::vector<Vec3f>& point_rgb, const TrainConfig& config);
    // Continues a saved state. Throws Error if the photos differ from the ones the state was trained on.
    Trainer(std::vector<TrainView> views, TrainState state);
    ~Trainer();

    // Which backend rasterizes (forward and backward); the rest of the iteration runs on the CPU. The CPU
    // backend unless told otherwise. Throws Error when the backend cannot run here.
    void set_backend(RasterBackend backend);

    // Runs iteration() + 1. Throws NonFiniteError (state untouched by that iteration's update) if a loss
    // term or a gradient is not finite.
    StepReport step();
    bool done() const { return state_.iteration >= state_.config.iterations; }
    std::int64_t iteration() const { return state_.iteration; }

    const TrainState& state() const { return state_; }
    TrainState& state() { return state_; }
    const std::vector<TrainView>& views() const { return views_; }
    // Each training photo's environment is exposure(i) x the lighting network's output for it
    // (exif_exposure_factors with config exif_exposure, else 1).
    const std::vector<float>& exposures() const { return exposure_; }
    ShCoeffs<float> environment(int view) const;
    // The ground seeds added to the SfM points at the start (config ground_seeds; none found or resumed:
    // found = false and no points).
    const GroundSeeds& ground() const { return ground_; }
    // Where the sky drawn behind the surfels ends below the horizon (config sky_horizon_*; the cameras'
    // mean up), and the ground drawn there (config ground_backdrop: the current surfels' ground albedo).
    SkyHorizon sky_horizon() const;
    // Which side of each surfel a camera sees (config grazing_side_degrees about the photos' up).
    SurfelSideRule side_rule() const { return {up_, float(state_.config.grazing_side_degrees)}; }
    // How config geometric_transfer_every bakes the transfer (model/visibility_transfer.h): the ray start and
    // the ground's layer thickness as fractions of the scene extent, config shadow_bounce.
    VisibilityTransferOptions geometric_transfer_options() const;
    // The training view used at a given iteration (a fresh permutation of the photos per epoch).
    int view_for_iteration(std::int64_t iteration) const;

    // Time spent in each phase since construction (seconds), for profiling and benchmarks.
    struct PhaseTimes {
        double shading = 0, raster_forward = 0, losses = 0, raster_backward = 0, shading_backward = 0,
               physical = 0, optimizer = 0, densify = 0;
    };
    const PhaseTimes& phase_times() const { return times_; }
    // The lighting network's gradient of the last step's loss (zero before the first step and in stage 2),
    // for the finite-difference tests.
    const LightingMlpGradients& lighting_gradients() const { return lighting_grads_; }

  private:
    // sky_horizon() with the ground albedo already made.
    SkyHorizon sky_horizon(const Vec3f& ground) const;
    struct Scratch;
    struct ViewMasks;
    void prepare_view_masks();
    void set_learning_rates(std::int64_t iteration);
    void render_step(std::int64_t iteration, Stage stage, StepReport& report);
    void physical_step(std::int64_t iteration, Stage stage, StepReport& report);
    // config geometric_transfer_every: whether this shadowed-stage iteration bakes the transfer, and the
    // bake.
    bool bakes_transfer(std::int64_t iteration) const;
    void bake_transfer();
    void densify_step(std::int64_t iteration, Stage stage, StepReport& report);
    // After densification: the prune goes on (prune_until_end) and painters of empty space are removed.
    void post_densification_prune(std::int64_t iteration, StepReport& report);
    // Renders every training photo's geometry and removes the surfels with more than
    // empty_space_prune_share of their blend weight on pixels that must stay empty, and at the `last`
    // iteration those whose weight summed over the photos is below min_contribution_pixels; with
    // min_ground_views, the weakly seen surfels below the cameras; counts them in `report`.
    void sweep_and_prune(bool last, StepReport& report);
    // The height along up_ of the lowest training camera: below it lies the ground min_ground_views watches.
    double lowest_camera_height() const;
    // The pixels of training photo `view` that must stay empty: its sky or an object's outside, or
    // without masks (with a sky background and lambda_background_alpha) the pixels whose sky the photo
    // already shows under its current light (the sky drawn with `horizon`); empty when the photo has none.
    std::vector<float> empty_pixels(int view, const SkyHorizon& horizon);
    void check_finite(std::int64_t iteration, const StepReport& report) const;
    void optimizer_step(std::int64_t iteration, Stage stage);

    std::vector<TrainView> views_;
    std::vector<ViewMasks> masks_;  // per view: what the photometric, alpha and regulariser losses act on
    GroundSeeds ground_;
    Vec3f up_{0, 0, 1};  // the photos' up (camera_up_direction): the horizon of the sky, background_alpha
    std::vector<float> exposure_;  // exposures()
    TrainState state_;
    std::unique_ptr<Scratch> scratch_;
    PhaseTimes times_;
    LightingMlpGradients lighting_grads_;      // of this iteration's loss
    SkyResidualGradients sky_residual_grads_;  // ... (empty without sky residuals)
    bool lighting_has_grad_ = false;
    int last_view_ = 0;  // the photo of the current iteration (its sky residual is stepped)
};

// Thrown when a loss term or gradient is not finite; `term` names it.
struct NonFiniteError : std::runtime_error {
    NonFiniteError(std::int64_t iteration_, std::string term_);
    std::int64_t iteration;
    std::string term;
};

}  // namespace lumigauss
