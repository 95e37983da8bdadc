#include "lumigauss/relight/light_fit.h"

#include <algorithm>
#include <cmath>
#include <span>

#include "lumigauss/io/image_metrics.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/render/background.h"
#include "lumigauss/render/blend_weights.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/train/adam.h"
#include "lumigauss/train/image_losses.h"
#include "lumigauss/train/lighting_mlp_gradients.h"
#include "lumigauss/train/physical_losses.h"
#include "lumigauss/train/sky_hemisphere_prior.h"
#include "lumigauss/train/view_shading_backward.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

constexpr int kShFloats = 3 * kShCount;
constexpr int kResidualFloats = 3 * kSh4Count;

// Flat k * 3 + channel layout for the optimizer.
void to_flat(const ShCoeffs<float>& sh, std::span<float> flat) {
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) flat[std::size_t(3 * k + c)] = sh.c[k][c];
}

ShCoeffs<float> from_flat(std::span<const float> flat) {
    ShCoeffs<float> sh;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) sh.c[k][c] = flat[std::size_t(3 * k + c)];
    return sh;
}

Sh4Coeffs<float> residual_from_flat(std::span<const float> flat) {
    Sh4Coeffs<float> r;
    for (int k = 0; k < kSh4Count; ++k)
        for (int c = 0; c < 3; ++c) r.c[k][c] = flat[std::size_t(3 * k + c)];
    return r;
}

void residual_to_flat(const Sh4Coeffs<float>& r, std::span<float> flat) {
    for (int k = 0; k < kSh4Count; ++k)
        for (int c = 0; c < 3; ++c) flat[std::size_t(3 * k + c)] = r.c[k][c];
}

std::vector<float> mean_embedding(const LightingMlp& mlp) {
    const std::vector<float>& table = mlp.param(MlpGroup::kEmbedding);
    std::vector<double> sum(kEmbeddingDim, 0.0);
    for (int i = 0; i < mlp.num_images(); ++i)
        for (int d = 0; d < kEmbeddingDim; ++d)
            sum[std::size_t(d)] += table[std::size_t(i * kEmbeddingDim + d)];
    std::vector<float> mean(kEmbeddingDim);
    for (int d = 0; d < kEmbeddingDim; ++d)
        mean[std::size_t(d)] = float(sum[std::size_t(d)] / mlp.num_images());
    return mean;
}

void check_inputs(const TrainedRun& run, const Camera& camera, const Image& photo, const Image& mask,
                  const LightFitOptions& o) {
    if (photo.width != camera.width || photo.height != camera.height || photo.channels != 3)
        throw Error("fit-light: the photo is " + std::to_string(photo.width) + "x" +
                    std::to_string(photo.height) + " with " + std::to_string(photo.channels) +
                    " channels; the camera needs " + std::to_string(camera.width) + "x" +
                    std::to_string(camera.height) + " RGB");
    if (!mask.pixels.empty() &&
        (mask.width != photo.width || mask.height != photo.height || mask.channels != 1))
        throw Error("fit-light: the mask must be one channel of the photo's size");
    if (!mask.pixels.empty() &&
        std::none_of(mask.pixels.begin(), mask.pixels.end(), [](float m) { return m > 0; }))
        throw Error("fit-light: the mask selects no pixel");
    if (o.iterations < 1) throw Error("fit-light: iterations must be >= 1");
    if (run.model.size() == 0) throw Error("fit-light: the model has no surfel");
    if (o.variable == LightVariable::Embedding && run.lighting.num_images() == 0)
        throw Error("fit-light: fitting an embedding needs a run with a lighting network (" + run.dir +
                    " has none); fit the SH instead");
    if (o.initial_embedding && o.initial_embedding->size() != std::size_t(kEmbeddingDim))
        throw Error("fit-light: an initial embedding has " + std::to_string(kEmbeddingDim) + " values");
}

// The light as Adam sees it: a flat parameter vector and the map from it to the SH (and back for the
// gradient).
class LightParameters {
  public:
    LightParameters(const TrainedRun& run, const LightFitOptions& o) : variable_(o.variable) {
        if (variable_ == LightVariable::Sh) {
            values_.resize(kShFloats);
            to_flat((o.initial_sh ? *o.initial_sh : default_initial_sh(run)).cast<float>(), values_);
            adam_ = AdamGroup("env_sh", values_.size(), o.sh_learning_rate, 1, 1e-15);
        } else {
            // A private copy of the network whose row 0 holds the embedding being fitted.
            mlp_ = run.lighting;
            values_ = o.initial_embedding ? *o.initial_embedding : mean_embedding(run.lighting);
            adam_ = AdamGroup("embedding", values_.size(), o.embedding_learning_rate, 1, 1e-15);
        }
        grads_.assign(values_.size(), 0.0f);
        base_lr_ = adam_.lr();
    }

    ShCoeffs<float> sh() {
        if (variable_ == LightVariable::Sh) return from_flat(values_);
        std::copy(values_.begin(), values_.end(), mlp_.param(MlpGroup::kEmbedding).begin());
        forward_ = mlp_.forward(0);
        return forward_.sh;
    }

    // dLoss/dSH of the light last returned by sh() -> dLoss/dvalues.
    void set_gradient(const ShCoeffs<float>& g_sh) {
        if (variable_ == LightVariable::Sh) {
            to_flat(g_sh, grads_);
            return;
        }
        mlp_grads_.reset(mlp_);
        mlp_grads_.backward(mlp_, forward_, g_sh);
        const std::vector<float>& g = mlp_grads_[MlpGroup::kEmbedding];
        std::copy(g.begin(), g.begin() + kEmbeddingDim, grads_.begin());
    }

    void step(double lr_factor) {
        adam_.set_lr(base_lr_ * lr_factor);
        adam_.step(values_, grads_);
    }

    const std::vector<float>& values() const { return values_; }

  private:
    LightVariable variable_;
    std::vector<float> values_, grads_;
    AdamGroup adam_;
    double base_lr_ = 0;
    LightingMlp mlp_;
    LightingMlpGradients mlp_grads_;
    LightingForward<float> forward_;
};

// The photo's own sky residual, fitted beside the light when the run learned one per training photo: Adam
// from zero, the learning rate and decay of the SH.
class SkyResidualParameter {
  public:
    SkyResidualParameter(bool active, const LightFitOptions& o)
        : values_(active ? kResidualFloats : 0, 0.0f), grads_(values_.size(), 0.0f) {
        if (active) adam_ = AdamGroup("sky_residual", values_.size(), o.sh_learning_rate, 1, 1e-15);
        base_lr_ = o.sh_learning_rate;
    }
    bool active() const { return !values_.empty(); }
    Sh4Coeffs<float> value() const { return active() ? residual_from_flat(values_) : Sh4Coeffs<float>{}; }
    void set_gradient(const Sh4Coeffs<float>& g) {
        if (active()) residual_to_flat(g, grads_);
    }
    void step(double lr_factor) {
        if (!active()) return;
        adam_.set_lr(base_lr_ * lr_factor);
        adam_.step(values_, grads_);
    }

  private:
    std::vector<float> values_, grads_;
    AdamGroup adam_;
    double base_lr_ = 0;
};

// One render of the frozen model under a light, its objective and the objective's gradient w.r.t. the SH
// (and the sky residual). A run trained with its sky behind the surfels is rendered so here too: the sky of
// the light being fitted (plus the photo's residual, when the run has them) fills what the surfels leave
// uncovered, and its pixels pull on the light only if they did in training (TrainedRun::sky_pins_light).
class FrozenViewObjective {
  public:
    FrozenViewObjective(const TrainedRun& run, const Camera& camera, const Image& photo, const Image& mask,
                        const LightFitOptions& o)
        : o_(o),
          camera_(camera),
          model_(GaussianModel::from_model(run.model, 1.0)),
          photo_(photo),
          mask_(mask.pixels.empty() ? Image(photo.width, photo.height, 1, 1.0f) : mask) {
        mode_ = o.shadowed ? ShadingMode::Shadowed : ShadingMode::Unshadowed;
        model_.activated(batch_);
        compute_view_normals(model_, camera_, normals_, run.side_rule);
        shape_ = ImageShape{photo.width, photo.height, 3};
        // The geometry is frozen, so the blending weights of one rasterisation serve every step: each
        // evaluation only re-shades the surfels and composites with them (and back), which is exact.
        shade_surfels(model_, uniform_irradiance_environment<float>(), mode_, normals_, batch_);
        weights_ = render_blend_weights(camera_, batch_, settings_, images_);
        if (run.sky_background) {
            rays_ = pixel_ray_directions(camera_);
            horizon_ = run.sky_horizon;
            sky_pins_light_ = run.sky_pins_light;
            with_residual_ = !run.sky_residuals.empty();
            lambda_residual_ = run.lambda_sky_residual;
            if (with_residual_ && run.lambda_sky_hemisphere > 0) init_hemisphere_prior(run);
        }
    }

    // Whether the photo gets a sky residual of its own.
    bool fits_sky_residual() const { return with_residual_; }

    struct Value {
        double loss = 0, psnr = 0;
        ShCoeffs<float> g_env{};
        Sh4Coeffs<float> g_residual{};
    };

    Value evaluate(const ShCoeffs<float>& env, const Sh4Coeffs<float>& residual, int iteration,
                   bool with_gradient) {
        Value v;
        shade_surfels(model_, env, mode_, normals_, batch_);
        composite(weights_, batch_.colors, batch_.channels, images_.color);
        if (!rays_.empty()) {
            sky_pixels(rays_, env, with_residual_ ? &residual : nullptr, sky_, horizon_);
            composite_background<float>(images_, sky_.colour, 0);
        }
        std::span<const float> rendered = images_.color;  // 3 channels in either single mode
        grad_.color.assign(with_gradient ? rendered.size() : 0, 0.0f);
        grad_.alpha.clear();  // the sky's backward adds to it; the frozen geometry never reads it
        std::span<float> g = grad_.color;
        const float w1 = float(1 - o_.lambda_dssim), w2 = float(o_.lambda_dssim);
        const double l1 = masked_l1_loss<float>(shape_, rendered, photo_.pixels, mask_.pixels, w1, g);
        const double dssim = masked_dssim_loss<float>(shape_, rendered, photo_.pixels, mask_.pixels, w2, g);
        const double env_loss = env_nonnegativity_loss(env, o_.env_samples, o_.seed, iteration,
                                                       with_gradient ? o_.lambda_env : 0.0, v.g_env);
        v.loss = w1 * l1 + w2 * dssim + o_.lambda_env * env_loss;
        if (with_residual_) {
            // As training: the residual only takes what the light cannot hold.
            double penalty = 0;
            for (int k = 0; k < kSh4Count; ++k) {
                penalty += double(dot(residual.c[k], residual.c[k]));
                v.g_residual.c[k] = float(2 * lambda_residual_) * residual.c[k];
            }
            v.loss += lambda_residual_ * penalty;
            if (sky_target_) {
                v.loss += lambda_hemisphere_ * sky_hemisphere_prior(unseen_sky_, env, residual, *sky_target_,
                                                                    lambda_hemisphere_, v.g_residual);
            }
        }
        v.psnr = fitted_psnr();
        if (with_gradient) add_render_gradient(env, v);
        return v;
    }

    double env_loss(const ShCoeffs<float>& env, int iteration) const {
        ShCoeffs<float> unused{};
        return env_nonnegativity_loss(env, o_.env_samples, o_.seed, iteration, 0.0, unused);
    }

    // True when the last render put some coverage on a pixel of the mask.
    bool sees_model() const {
        for (std::size_t p = 0; p < mask_.pixels.size(); ++p)
            if (mask_.pixels[p] > 0 && images_.alpha[p] > 1e-4f) return true;
        return false;
    }

  private:
    // As training's prior on the photo's sky (train/sky_hemisphere_prior.h). The fit has no sky mask: the
    // photo's sky is taken where the frozen surfels leave the photo uncovered above the horizon.
    void init_hemisphere_prior(const TrainedRun& run) {
        const std::size_t pixels = rays_.size();
        std::vector<float> seen(pixels, 0.0f);
        for (std::size_t p = 0; p < pixels; ++p)
            if (images_.alpha[p] < 0.5f && mask_.pixels[p] > 0 && dot(rays_[p], run.sky_horizon.up) > 0)
                seen[p] = 1.0f;
        sky_target_ = mean_sky_radiance(photo_.pixels, seen, kSkyHemisphereMinPixels);
        unseen_sky_ = directions_out_of_view(
            upper_hemisphere_directions(run.sky_horizon.up, kSkyHemisphereDirections), camera_);
        lambda_hemisphere_ = run.lambda_sky_hemisphere;
    }

    void add_render_gradient(const ShCoeffs<float>& env, Value& v) {
        ShCoeffs<float>& g_env = v.g_env;
        if (!rays_.empty()) {
            g_sky_.assign(sky_.colour.size(), 0.0f);
            composite_background_backward<float>(images_, sky_.colour, 0, grad_, g_sky_);
            const SkyGrads g = sky_pixels_backward(rays_, sky_, g_sky_, {}, with_residual_);
            if (sky_pins_light_)
                for (int k = 0; k < kShCount; ++k) g_env.c[k] = g_env.c[k] + g.env.c[k];
            if (with_residual_)
                for (int k = 0; k < kSh4Count; ++k) v.g_residual.c[k] = v.g_residual.c[k] + g.residual.c[k];
        }
        g_colors_.resize(batch_.colors.size());
        composite_backward(weights_, grad_.color, batch_.channels, g_colors_);
        model_.zero_grad();  // the model's own gradients are a by-product here, never used
        const ShCoeffs<float> g_shading = shade_surfels_backward(model_, env, mode_, normals_, g_colors_);
        for (int k = 0; k < kShCount; ++k) g_env.c[k] = g_env.c[k] + g_shading.c[k];
    }

    double fitted_psnr() const {
        Image rendered(photo_.width, photo_.height, 3);
        rendered.pixels = images_.color;
        return psnr_from_mse(masked_mse(clamp01(rendered), photo_, mask_));
    }

    const LightFitOptions& o_;
    const Camera& camera_;
    GaussianModel model_;  // shading's backward writes (unused) gradients into it
    const Image& photo_;
    Image mask_;  // all ones without a mask
    ShadingMode mode_;
    ImageShape shape_;
    ViewNormals normals_;
    SurfelBatch<float> batch_;
    RasterSettings<float> settings_;
    RasterImages<float> images_;
    BlendWeights weights_;
    RasterImageGrads<float> grad_;
    std::vector<float> g_colors_;
    std::vector<Vec3f> rays_;  // every pixel's world ray, when the sky is drawn behind; else empty
    SkyHorizon horizon_;
    bool sky_pins_light_ = true, with_residual_ = false;
    double lambda_residual_ = 0, lambda_hemisphere_ = 0;
    std::optional<Vec3f> sky_target_;  // the hemisphere prior's target radiance (none: no prior)
    std::vector<Vec3f> unseen_sky_;
    SkyPixels sky_;
    std::vector<float> g_sky_;
};

}  // namespace

const char* light_variable_name(LightVariable v) {
    return v == LightVariable::Sh ? "sh" : "embedding";
}

Image fitted_colour(const TrainedRun& run, const Camera& camera, const RasterImages<float>& relit, int first,
                    const ShCoeffs<double>& light, const Sh4Coeffs<float>* sky_residual) {
    Image colour = raster_channels(relit, first, 3);
    if (run.sky_background)
        colour = over_background_image(colour, alpha_image(relit),
                                       sky_image(camera, light.cast<float>(), sky_residual, run.sky_horizon));
    return clamp01(colour);
}

Image fitted_colour(const TrainedRun& run, const Camera& camera, const RasterImages<float>& relit, int first,
                    const LightFitResult& fit) {
    return fitted_colour(run, camera, relit, first, fit.sh, fit.sky_residual ? &*fit.sky_residual : nullptr);
}

ShCoeffs<double> default_initial_sh(const TrainedRun& run) {
    ShCoeffs<double> sh{};
    const int n = int(run.image_names.size());
    if (n == 0 || run.lighting.num_images() == 0) return uniform_irradiance_environment<double>();
    for (int i = 0; i < n; ++i) {
        const ShCoeffs<double> l = run.learned_sh(i);
        for (int k = 0; k < kShCount; ++k) sh.c[k] = sh.c[k] + l.c[k] * (1.0 / n);
    }
    return sh;
}

LightFitResult fit_light(const TrainedRun& run, const Camera& camera, const Image& photo, const Image& mask,
                         const LightFitOptions& options) {
    check_inputs(run, camera, photo, mask, options);
    LightParameters light(run, options);
    FrozenViewObjective objective(run, camera, photo, mask, options);
    SkyResidualParameter residual(objective.fits_sky_residual(), options);

    // The best iterate so far: its parameters, its light and its scores (the loss and PSNR evaluate() gave
    // for those parameters, before the step that followed).
    struct Iterate {
        std::vector<float> values;
        ShCoeffs<float> env{};
        Sh4Coeffs<float> residual{};
        double loss = std::numeric_limits<double>::infinity(), psnr = 0;
    } best;
    const auto keep_if_best = [&](const ShCoeffs<float>& env, double loss, double psnr) {
        if (std::isfinite(loss) && loss < best.loss)
            best = {light.values(), env, residual.value(), loss, psnr};
    };
    LightFitResult result;
    const double decay = std::log(options.final_lr_fraction);
    for (int it = 0; it < options.iterations; ++it) {
        const ShCoeffs<float> env = light.sh();
        const auto v = objective.evaluate(env, residual.value(), it, true);
        if (!std::isfinite(v.loss))
            throw Error("fit-light: the objective became non-finite at iteration " + std::to_string(it));
        if (it == 0) {
            if (!objective.sees_model())
                throw Error("fit-light: no surfel of the model covers a pixel the fit uses (wrong camera?)");
            result.initial_loss = v.loss, result.initial_psnr = v.psnr;
        }
        keep_if_best(env, v.loss, v.psnr);
        if (options.progress) options.progress(it, v.loss, v.psnr);
        light.set_gradient(v.g_env);
        residual.set_gradient(v.g_residual);
        const double lr_factor = std::exp(decay * it / std::max(1, options.iterations - 1));
        light.step(lr_factor);
        residual.step(lr_factor);
    }
    // The last step's result has not been scored yet.
    const ShCoeffs<float> last = light.sh();
    const auto v = objective.evaluate(last, residual.value(), options.iterations, false);
    keep_if_best(last, v.loss, v.psnr);

    result.sh = best.env.cast<double>();
    if (residual.active()) result.sky_residual = best.residual;
    if (options.variable == LightVariable::Embedding) result.embedding = best.values;
    result.iterations = options.iterations;
    result.final_loss = best.loss;
    result.final_psnr = best.psnr;
    result.env_loss = objective.env_loss(best.env, options.iterations);
    return result;
}

}  // namespace lumigauss
