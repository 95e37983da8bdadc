#pragma once
// The trainable surfel model of the official LumiGauss (`scene/gaussian_model.py:GaussianModel`): the surfels
// of model/surfel_model.h plus what only training needs, one Adam group per parameter, the gradient buffers,
// the xyz learning-rate schedule and the densification bookkeeping (research/lumigauss_official.md 2.1, 5;
// research/2dgs_rasterizer.md 6). A finished model is its SurfelModel part (slicing a GaussianModel into a
// SurfelModel drops the optimizer state).
// The official code has separate Adam groups for f_dc_* and f_rest_*; with one learning rate for both and
// both always receiving gradients together, one group of 27 per side is element-for-element identical.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lumigauss/model/surfel_model.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/train/adam.h"

namespace lumigauss {

// Official defaults (training_setup, 5): xyz decays 1.6e-4 -> 1.6e-6 (x spatial_lr_scale) over 30000 steps.
struct ModelLearningRates {
    double position_init = 1.6e-4;
    double position_final = 1.6e-6;
    double position_delay_mult = 0.01;  // inert: delay steps are 0
    std::int64_t position_max_steps = 30000;
    double transfer = 0.002;  // f_dc and f_rest, positive and negative (rest not divided by 20)
    double opacity = 0.05;
    double scaling = 0.005;
    double rotation = 0.001;
    double albedo = 0.0025;
};

// Official densification thresholds (5): grad 2e-4, percent_dense 0.01, min opacity 0.05, 20 px, 0.1 extent.
struct DensifyOptions {
    double percent_dense = 0.01;
    double world_size_fraction = 0.1;  // prune max scale > 0.1 * extent (only with a screen-size limit)
    int split_children = 2;
    // The official densification_postfix zeroes max_radii2D before the prune reads it, so the screen-size
    // rule never fires; true replicates that, false prunes by the radii accumulated since the last reset.
    bool faithful_radii_reset = true;
};

struct DensifyReport {
    std::size_t cloned = 0, split = 0, pruned = 0;
};

class GaussianModel : public SurfelModel {
  public:
    GaussianModel() = default;

    // create_from_pcd + training_setup. point_rgb in [0, 1]. spatial_lr_scale = cameras_extent. Rotations
    // are random as officially, or with `orient_from_points` turned so that each surfel's normal is the
    // normal of its point's neighbourhood (model/point_normals.h).
    static GaussianModel from_points(const std::vector<Vec3f>& xyz, const std::vector<Vec3f>& rgb,
                                     double spatial_lr_scale, std::uint64_t seed,
                                     const ModelLearningRates& lr = {}, bool orient_from_points = false);
    // Wraps a finished model (e.g. a loaded PLY) with fresh optimizer state.
    static GaussianModel from_model(SurfelModel model, double spatial_lr_scale,
                                    const ModelLearningRates& lr = {});
    // The same from raw parameters: every vector must hold size * width(p) floats.
    static GaussianModel from_raw(std::vector<std::vector<float>> raw, double spatial_lr_scale,
                                  const ModelLearningRates& lr = {});
    AdamGroup& adam(ModelParam p) { return adam_[int(p)]; }
    const AdamGroup& adam(ModelParam p) const { return adam_[int(p)]; }
    // The gradient buffer of a group; asking for it mutably marks the group as having a gradient this
    // iteration (torch zero_grad(set_to_none=True): groups without a gradient are not stepped).
    std::span<float> grad(ModelParam p);
    std::span<const float> grad(ModelParam p) const { return grads_[int(p)]; }
    bool has_grad(ModelParam p) const { return has_grad_[int(p)]; }
    const ModelLearningRates& learning_rates() const { return lr_; }
    double spatial_lr_scale() const { return spatial_lr_scale_; }

    // Chain rule from activated-value gradients into the raw-gradient buffers (added). Empty vectors in
    // `g` are skipped; colour and mean2d entries are not used here.
    void accumulate_grads_from_activated(const SurfelGrads<float>& g);

    void zero_grad();
    // Forgets this iteration's gradient of one group, so step() skips it (what torch does after a
    // parameter tensor is replaced, e.g. by the opacity reset).
    void drop_grad(ModelParam p);
    // One Adam step on every group that received a gradient; the xyz learning rate first follows the
    // exponential schedule at `iteration` (update_learning_rate).
    void step(std::int64_t iteration);
    double position_lr(std::int64_t iteration) const;

    // Densification statistics (add_densification_stats plus the max_radii2D update of train.py), for one
    // rendered view: for each visible surfel, accum += |(g_x W/2, g_y H/2)| (mean2d in pixels -> NDC units),
    // count += 1, max_radius = max(max_radius, radius).
    // `damping` (empty, or one factor per surfel) scales each gradient norm before it is accumulated.
    void add_densification_stats(std::span<const float> mean2d_grad, std::span<const std::uint8_t> visible,
                                 std::span<const float> radii, int image_width, int image_height,
                                 std::span<const float> damping = {});
    const std::vector<float>& grad_accum() const { return grad_accum_; }
    const std::vector<float>& grad_count() const { return grad_count_; }
    const std::vector<float>& max_radii() const { return max_radii_; }
    // Puts back saved statistics (checkpoints); each must hold size() values.
    void restore_densification_stats(std::vector<float> accum, std::vector<float> count,
                                     std::vector<float> radii);

    // densify_and_clone, densify_and_split, then prune (2DGS densify_and_prune). max_screen_size <= 0
    // disables the screen/world-size rules (the official passes None before iteration 3000).
    DensifyReport densify_and_prune(double grad_threshold, double min_opacity, double extent,
                                    double max_screen_size, std::uint64_t seed,
                                    const DensifyOptions& opt = {});
    // The prune alone, for the iterations after densification: removes surfels with opacity < min_opacity or
    // (max_world_scale > 0) a scale above max_world_scale. Returns how many were removed.
    std::size_t prune(double min_opacity, double max_world_scale);
    // opacity <- min(opacity, ceiling) (as logit; officially 0.01), opacity moments zeroed
    // (replace_tensor_to_optimizer).
    void reset_opacity(float ceiling);
    // Keeps rows with keep[i] != 0 in every parameter, gradient, Adam state and statistic.
    void keep_rows(std::span<const std::uint8_t> keep);

  private:
    void init_optimizer(const ModelLearningRates& lr, double spatial_lr_scale);
    // densification_postfix: appends rows (copies of the given raw values), zero moments, stats reset.
    void append_rows(const std::vector<std::vector<float>>& rows, bool reset_radii);
    void reset_stats();
    std::size_t clone(const std::vector<float>& grads, double threshold, double extent, double percent_dense,
                      bool reset_radii);
    std::size_t split(const std::vector<float>& grads, double threshold, double extent, double percent_dense,
                      int children, std::uint64_t seed, bool reset_radii);

    std::vector<float> grads_[kModelParamCount];
    bool has_grad_[kModelParamCount]{};
    AdamGroup adam_[kModelParamCount];
    ExponLrSchedule xyz_schedule_;
    ModelLearningRates lr_;
    double spatial_lr_scale_ = 1;
    std::vector<float> grad_accum_, grad_count_, max_radii_;  // xyz_gradient_accum, denom, max_radii2D
};

}  // namespace lumigauss
