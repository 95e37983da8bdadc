#include "lumigauss/train/gaussian_model.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/knn.h"
#include "lumigauss/model/point_normals.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/rng.h"

namespace lumigauss {

namespace {

// Random streams of the model, distinct from the synthetic-scene purposes in synth/rng.h.
constexpr std::uint64_t kRotationStream = 0x524f54;  // "ROT"
constexpr std::uint64_t kSplitStream = 0x53504c;     // "SPL"

}  // namespace

GaussianModel GaussianModel::from_points(const std::vector<Vec3f>& xyz, const std::vector<Vec3f>& rgb,
                                         double spatial_lr_scale, std::uint64_t seed,
                                         const ModelLearningRates& lr, bool orient_from_points) {
    if (xyz.size() != rgb.size()) throw Error("GaussianModel: point and colour counts differ");
    const std::size_t n = xyz.size();
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (ModelParam p : kAllModelParams) raw[int(p)].reserve(n * std::size_t(width(p)));
    // dist2 = clamp_min(distCUDA2(points), 1e-7); scales = log(sqrt(dist2)) on both axes.
    const std::vector<double> dist2 = mean_sq_dist_knn(xyz, 3);
    Rng rot_rng(hash_keys(seed, kRotationStream));
    const float opacity = inverse_sigmoid(0.1f);
    const std::vector<Vec3f> normals = orient_from_points ? point_normals(xyz) : std::vector<Vec3f>{};
    for (std::size_t i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) raw[0].push_back(xyz[i][a]);
        // torch.rand((N, 4)): uniform [0, 1)^4, normalised where used.
        for (int a = 0; a < 4; ++a) raw[1].push_back(float(rot_rng.uniform()));
        if (orient_from_points) {
            const Vec4<double> q = quaternion_with_normal(normals[i].cast<double>());
            for (int a = 0; a < 4; ++a) raw[1][raw[1].size() - 4 + std::size_t(a)] = float(q[a]);
        }
        const float d2 = std::max(float(dist2[i]), 1e-7f);
        const float log_scale = std::log(std::sqrt(d2));
        raw[2].push_back(log_scale), raw[2].push_back(log_scale);
        raw[3].push_back(opacity);
        // RGB2SH: (rgb - 0.5) / C0, so that the initial albedo max(0, C0 a + 0.5) is the point colour.
        for (int c = 0; c < 3; ++c) raw[4].push_back(float((double(rgb[i][c]) - 0.5) / sh_const::kY00));
        raw[5].insert(raw[5].end(), kTransferStored, 0.01f);  // every transfer value 0.01 (2.1)
        raw[6].insert(raw[6].end(), kTransferStored, 0.01f);
    }
    return from_raw(std::move(raw), spatial_lr_scale, lr);
}

GaussianModel GaussianModel::from_model(SurfelModel model, double spatial_lr_scale,
                                        const ModelLearningRates& lr) {
    GaussianModel m;
    static_cast<SurfelModel&>(m) = std::move(model);
    for (ModelParam p : kAllModelParams) m.grads_[int(p)].assign(m.params_[int(p)].size(), 0.0f);
    m.init_optimizer(lr, spatial_lr_scale);
    m.reset_stats();
    return m;
}

GaussianModel GaussianModel::from_raw(std::vector<std::vector<float>> raw, double spatial_lr_scale,
                                      const ModelLearningRates& lr) {
    return from_model(SurfelModel::from_raw(std::move(raw)), spatial_lr_scale, lr);
}

void GaussianModel::init_optimizer(const ModelLearningRates& lr, double spatial_lr_scale) {
    lr_ = lr;
    spatial_lr_scale_ = spatial_lr_scale;
    xyz_schedule_ = {lr.position_init * spatial_lr_scale, lr.position_final * spatial_lr_scale, 0,
                     lr.position_delay_mult, lr.position_max_steps};
    const double rates[kModelParamCount] = {lr.position_init * spatial_lr_scale,
                                            lr.rotation,
                                            lr.scaling,
                                            lr.opacity,
                                            lr.albedo,
                                            lr.transfer,
                                            lr.transfer};
    for (ModelParam p : kAllModelParams)
        adam_[int(p)] = AdamGroup(name(p), params_[int(p)].size(), rates[int(p)], width(p));
}

std::span<float> GaussianModel::grad(ModelParam p) {
    has_grad_[int(p)] = true;
    return grads_[int(p)];
}

void GaussianModel::accumulate_grads_from_activated(const SurfelGrads<float>& g) {
    auto add = [this](ModelParam p, const std::vector<float>& src, auto&& chain) {
        if (src.empty()) return;
        if (src.size() != params_[int(p)].size())
            throw Error(std::string("accumulate_grads_from_activated: '") + name(p) + "' has the wrong size");
        std::span<float> dst = grad(p);
        for (std::size_t i = 0; i < src.size(); ++i) dst[i] += chain(i, src[i]);
    };
    add(ModelParam::Xyz, g.means, [](std::size_t, float v) { return v; });
    add(ModelParam::Rotation, g.quats, [](std::size_t, float v) { return v; });  // raw quats go in as is
    const auto& s = param(ModelParam::Scaling);
    add(ModelParam::Scaling, g.scales, [&s](std::size_t i, float v) { return v * std::exp(s[i]); });
    const auto& o = param(ModelParam::Opacity);
    add(ModelParam::Opacity, g.opacities, [&o](std::size_t i, float v) {
        const float a = sigmoid(o[i]);
        return v * a * (1.0f - a);
    });
}

void GaussianModel::zero_grad() {
    for (ModelParam p : kAllModelParams) {
        std::fill(grads_[int(p)].begin(), grads_[int(p)].end(), 0.0f);
        has_grad_[int(p)] = false;
    }
}

double GaussianModel::position_lr(std::int64_t iteration) const {
    return xyz_schedule_(iteration);
}

void GaussianModel::step(std::int64_t iteration) {
    adam(ModelParam::Xyz).set_lr(position_lr(iteration));
    for (ModelParam p : kAllModelParams)
        if (has_grad_[int(p)]) adam_[int(p)].step(params_[int(p)], grads_[int(p)]);
}

void GaussianModel::drop_grad(ModelParam p) {
    std::fill(grads_[int(p)].begin(), grads_[int(p)].end(), 0.0f);
    has_grad_[int(p)] = false;
}

void GaussianModel::restore_densification_stats(std::vector<float> accum, std::vector<float> count,
                                                std::vector<float> radii) {
    if (accum.size() != size() || count.size() != size() || radii.size() != size())
        throw Error("restore_densification_stats: saved statistics do not match the model size");
    grad_accum_ = std::move(accum);
    grad_count_ = std::move(count);
    max_radii_ = std::move(radii);
}

void GaussianModel::reset_stats() {
    grad_accum_.assign(size(), 0.0f);
    grad_count_.assign(size(), 0.0f);
    max_radii_.assign(size(), 0.0f);
}

void GaussianModel::add_densification_stats(std::span<const float> mean2d_grad,
                                            std::span<const std::uint8_t> visible,
                                            std::span<const float> radii, int image_width, int image_height,
                                            std::span<const float> damping) {
    const std::size_t n = size();
    if (mean2d_grad.size() != 2 * n || visible.size() != n || radii.size() != n ||
        (!damping.empty() && damping.size() != n))
        throw Error("add_densification_stats: sizes differ from the model");
    // Pixel x = (ndc_x + 1) W / 2 - 0.5, so dL/d(ndc_x) = dL/dx * W / 2 (2dgs_rasterizer.md 4.2).
    const float hw = 0.5f * float(image_width), hh = 0.5f * float(image_height);
    for (std::size_t i = 0; i < n; ++i) {
        if (!visible[i]) continue;
        const float gx = mean2d_grad[2 * i] * hw, gy = mean2d_grad[2 * i + 1] * hh;
        grad_accum_[i] += std::sqrt(gx * gx + gy * gy) * (damping.empty() ? 1.0f : damping[i]);
        grad_count_[i] += 1.0f;
        max_radii_[i] = std::max(max_radii_[i], radii[i]);
    }
}

void GaussianModel::append_rows(const std::vector<std::vector<float>>& rows, bool reset_radii) {
    for (ModelParam p : kAllModelParams) {
        auto& v = params_[int(p)];
        v.insert(v.end(), rows[int(p)].begin(), rows[int(p)].end());
        grads_[int(p)].resize(v.size(), 0.0f);
        // cat_tensors_to_optimizer: new rows start with zero moments; the step count is kept.
        adam_[int(p)].append_rows(rows[int(p)].size() / std::size_t(width(p)));
    }
    // densification_postfix zeroes all statistics, max_radii2D included (see DensifyOptions).
    std::vector<float> radii = std::move(max_radii_);
    reset_stats();
    if (!reset_radii) std::copy(radii.begin(), radii.end(), max_radii_.begin());
}

void GaussianModel::keep_rows(std::span<const std::uint8_t> keep) {
    if (keep.size() != size()) throw Error("GaussianModel::keep_rows: mask size differs from the model");
    keep_parameter_rows(keep);
    for (ModelParam p : kAllModelParams) {
        lumigauss::keep_rows(grads_[int(p)], width(p), keep);
        adam_[int(p)].keep_rows(keep);
    }
    lumigauss::keep_rows(grad_accum_, 1, keep);
    lumigauss::keep_rows(grad_count_, 1, keep);
    lumigauss::keep_rows(max_radii_, 1, keep);
}

namespace {

float max_scale(const std::vector<float>& log_scales, std::size_t i) {
    return std::exp(std::max(log_scales[2 * i], log_scales[2 * i + 1]));
}

}  // namespace

std::size_t GaussianModel::clone(const std::vector<float>& grads, double threshold, double extent,
                                 double percent_dense, bool reset_radii) {
    std::vector<std::vector<float>> rows(kModelParamCount);
    std::size_t count = 0;
    const auto& s = param(ModelParam::Scaling);
    for (std::size_t i = 0; i < grads.size(); ++i) {
        if (!(grads[i] >= threshold) || !(max_scale(s, i) <= percent_dense * extent)) continue;
        for (ModelParam p : kAllModelParams) {
            const auto w = std::size_t(width(p));
            const auto& v = params_[int(p)];
            rows[int(p)].insert(rows[int(p)].end(), v.begin() + std::ptrdiff_t(i * w),
                                v.begin() + std::ptrdiff_t((i + 1) * w));
        }
        ++count;
    }
    append_rows(rows,
                reset_radii);  // called even with nothing selected, as officially (it resets the statistics)
    return count;
}

std::size_t GaussianModel::split(const std::vector<float>& grads, double threshold, double extent,
                                 double percent_dense, int children, std::uint64_t seed, bool reset_radii) {
    const std::size_t n = size();
    const auto& s = param(ModelParam::Scaling);
    std::vector<std::size_t> selected;
    // padded_grad: rows appended by the clone have gradient 0 and are never split.
    for (std::size_t i = 0; i < std::min(n, grads.size()); ++i)
        if (grads[i] >= threshold && max_scale(s, i) > percent_dense * extent) selected.push_back(i);
    std::vector<std::vector<float>> rows(kModelParamCount);
    Rng rng(hash_keys(seed, kSplitStream, n));
    const auto& xyz = param(ModelParam::Xyz);
    const auto& rot = param(ModelParam::Rotation);
    // .repeat(N, 1): all selected rows once, then all again (not interleaved).
    for (int c = 0; c < children; ++c)
        for (std::size_t i : selected) {
            const double su = std::exp(double(s[2 * i])), sv = std::exp(double(s[2 * i + 1]));
            // samples ~ N(0, diag(s_u, s_v, 0)) in the local frame, rotated by R(q) into the tangent plane.
            const double u = rng.normal() * su, v = rng.normal() * sv;
            const Vec4<double> q = normalize_quaternion(
                Vec4<double>{rot[4 * i], rot[4 * i + 1], rot[4 * i + 2], rot[4 * i + 3]});
            const Mat3<double> r = rotation_from_unit_quaternion(q);
            for (int a = 0; a < 3; ++a)
                rows[0].push_back(float(r.m[a][0] * u + r.m[a][1] * v + double(xyz[3 * i + std::size_t(a)])));
            for (ModelParam p : kAllModelParams) {
                if (p == ModelParam::Xyz) continue;
                const auto w = std::size_t(width(p));
                const auto& src = params_[int(p)];
                for (std::size_t k = 0; k < w; ++k) {
                    float value = src[i * w + k];
                    // scaling_inverse_activation(scaling / (0.8 N))
                    if (p == ModelParam::Scaling)
                        value = float(std::log(std::exp(double(value)) / (0.8 * children)));
                    rows[int(p)].push_back(value);
                }
            }
        }
    append_rows(rows, reset_radii);
    // Parents are removed; children (appended) are kept.
    std::vector<std::uint8_t> keep(size(), 1);
    for (std::size_t i : selected) keep[i] = 0;
    keep_rows(keep);
    return selected.size();
}

DensifyReport GaussianModel::densify_and_prune(double grad_threshold, double min_opacity, double extent,
                                               double max_screen_size, std::uint64_t seed,
                                               const DensifyOptions& opt) {
    DensifyReport report;
    std::vector<float> grads(size());
    for (std::size_t i = 0; i < grads.size(); ++i)  // grads[grads.isnan()] = 0.0
        grads[i] = grad_count_[i] > 0 ? grad_accum_[i] / grad_count_[i] : 0.0f;
    report.cloned = clone(grads, grad_threshold, extent, opt.percent_dense, opt.faithful_radii_reset);
    report.split = split(grads, grad_threshold, extent, opt.percent_dense, opt.split_children, seed,
                         opt.faithful_radii_reset);

    const auto& s = param(ModelParam::Scaling);
    const auto& o = param(ModelParam::Opacity);
    std::vector<std::uint8_t> keep(size(), 1);
    for (std::size_t i = 0; i < size(); ++i) {
        bool prune = sigmoid(o[i]) < min_opacity;
        if (max_screen_size > 0) {
            prune = prune || max_radii_[i] > max_screen_size;  // zero here when faithful (postfix reset)
            prune = prune || max_scale(s, i) > opt.world_size_fraction * extent;
        }
        keep[i] = prune ? 0 : 1;
        report.pruned += prune ? 1 : 0;
    }
    keep_rows(keep);
    return report;
}

std::size_t GaussianModel::prune(double min_opacity, double max_world_scale) {
    const auto& s = param(ModelParam::Scaling);
    const auto& o = param(ModelParam::Opacity);
    std::vector<std::uint8_t> keep(size(), 1);
    std::size_t removed = 0;
    for (std::size_t i = 0; i < size(); ++i) {
        const bool too_big = max_world_scale > 0 && max_scale(s, i) > max_world_scale;
        if (sigmoid(o[i]) < min_opacity || too_big) keep[i] = 0, ++removed;
    }
    if (removed > 0) keep_rows(keep);
    return removed;
}

void GaussianModel::reset_opacity(float ceiling) {
    auto& o = param(ModelParam::Opacity);
    for (float& v : o) v = inverse_sigmoid(std::min(sigmoid(v), ceiling));
    adam(ModelParam::Opacity).reset_moments();
}

}  // namespace lumigauss
