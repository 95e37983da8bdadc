#include "lumigauss/eval/light_scale.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "lumigauss/relight/relit_render.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

double irradiance_weight(int j) {
    const double a = j == 0 ? rh_const::kA0 : (j < 4 ? rh_const::kA1 : rh_const::kA2);
    return a * a;
}

namespace {

// The luminance DC and band-1 vector of an SH light.
double luminance(const Vec3d& rgb) {
    return (rgb[0] + rgb[1] + rgb[2]) / 3;
}
Vec3d band1(const ShCoeffs<double>& sh) {
    return {luminance(sh.c[1]), luminance(sh.c[2]), luminance(sh.c[3])};
}

// The median of the finite values; NaN when there is none.
double finite_median(std::vector<double> values) {
    std::erase_if(values, [](double v) { return !std::isfinite(v); });
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t mid = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(mid), values.end());
    if (values.size() % 2 == 1) return values[mid];
    return 0.5 * (values[mid] + *std::max_element(values.begin(), values.begin() + std::ptrdiff_t(mid)));
}

}  // namespace

LightDirection light_direction(const ShCoeffs<double>& learned, const ShCoeffs<double>& truth) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double learned_dc = luminance(learned.c[0]), true_dc = luminance(truth.c[0]);
    const Vec3d l = band1(learned), t = band1(truth);
    if (!(learned_dc > 0) || !(true_dc > 0) || !(length(t) >= 0.05 * true_dc)) return {nan, nan};
    const double strength = (length(l) / learned_dc) / (length(t) / true_dc);
    // The band-1 coefficients are a fixed signed permutation of the dipole's x, y, z: angles carry over.
    const double cosine = length(l) > 0 ? dot(l, t) / (length(l) * length(t)) : nan;
    return {strength, std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi};
}

LightScaleFit fit_light_scale(const std::vector<ShCoeffs<double>>& learned,
                              const std::vector<ShCoeffs<double>>& truth, const std::vector<double>& exposure,
                              const std::vector<std::string>& names) {
    if (learned.empty()) throw Error("light scale: no training photo to fit it on");
    if (learned.size() != truth.size() || learned.size() != exposure.size() ||
        (!names.empty() && names.size() != learned.size()))
        throw Error("light scale: the lists of learned SH, true SH and exposures differ in length");
    LightScaleFit fit;
    fit.names = names;
    double lt = 0, tt = 0, ll = 0;
    for (std::size_t i = 0; i < learned.size(); ++i) {
        double lt_i = 0, tt_i = 0;
        for (int j = 0; j < kShCount; ++j) {
            const double w = irradiance_weight(j);
            for (int c = 0; c < 3; ++c) {
                const double l = learned[i].c[j][c], t = truth[i].c[j][c];
                lt_i += w * l * t, tt_i += w * t * t, ll += w * l * l;
            }
        }
        const double e = exposure[i];
        lt += e * lt_i, tt += e * e * tt_i;
        fit.per_photo.push_back(tt_i > 0 ? lt_i / (e * tt_i) : std::numeric_limits<double>::quiet_NaN());
        fit.direction.push_back(light_direction(learned[i], truth[i]));
    }
    std::vector<double> strengths, errors;
    for (const LightDirection& d : fit.direction)
        strengths.push_back(d.strength), errors.push_back(d.error_deg);
    fit.median_direction_strength = finite_median(strengths);
    fit.median_direction_error_deg = finite_median(errors);
    if (!(tt > 0)) throw Error("light scale: the true lighting of every training photo is zero");
    fit.scale = lt / tt;
    // sum w |L - k e T|^2 = ll - 2 k lt + k^2 tt, at the optimum ll - k lt.
    const double residual = std::max(0.0, ll - fit.scale * lt);
    fit.relative_residual = ll > 0 ? std::sqrt(residual / ll) : 0.0;
    return fit;
}

LightScaleFit fit_run_light_scale(const RelightableRun& run, const GtSceneMeta& meta,
                                  const std::vector<std::string>& exclude) {
    if (run.image_names.empty()) return {};  // a bare PLY: no learned light to scale
    std::vector<ShCoeffs<double>> learned, truth;
    std::vector<double> exposure;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < run.image_names.size(); ++i) {
        const GtImageMeta* m = meta.find(run.image_names[i]);
        if (!m || m->split != "train") continue;  // never fit on a test photo
        if (std::find(exclude.begin(), exclude.end(), m->name) != exclude.end()) continue;
        learned.push_back(run.learned_sh[i]);
        truth.push_back(load_condition_sh(meta, m->condition));
        exposure.push_back(m->exposure);
        names.push_back(m->name);
    }
    if (learned.empty())
        fail_in_file(meta.meta_path, "none of the run's " + std::to_string(run.image_names.size()) +
                                         " training photos is listed with split \"train\"");
    return fit_light_scale(learned, truth, exposure, names);
}

std::optional<std::array<double, 3>> fit_image_light_scale(const RelightableRun& run, const Dataset& scene,
                                                           const GtSceneMeta& meta,
                                                           const std::vector<std::string>& exclude,
                                                           RasterBackend backend) {
    RelitRenderer renderer(run.model, backend, run.side_rule);
    std::array<double, 3> rp{}, rr{};
    for (const View* v : scene.split(Split::Train)) {
        const GtImageMeta* im = meta.find(v->name);
        if (im == nullptr || std::find(exclude.begin(), exclude.end(), v->name) != exclude.end()) continue;
        const RasterImages<float>& relit = renderer.render(v->camera, scaled_true_env(meta, *im, {1, 1, 1}));
        const Image photo = scene.load_image(*v);
        bool has_gt_mask = false;
        const Image mask = evaluation_mask(meta, scene, *v, has_gt_mask);
        for (std::size_t q = 0; q < mask.pixels.size(); ++q) {
            if (!(mask.pixels[q] > 0.5f) || relit.alpha[q] <= 0.5f) continue;
            const std::size_t i = 3 * q, o = std::size_t(relit.channels) * q + kRelitShadowed;
            // A clipped photo pixel says only "at least 1": it would pull the scale down.
            if (std::max({photo.pixels[i], photo.pixels[i + 1], photo.pixels[i + 2]}) >= 0.99f) continue;
            for (std::size_t c = 0; c < 3; ++c) {
                const double r = relit.color[o + c], p = photo.pixels[i + c];
                if (!std::isfinite(r)) continue;
                rp[c] += r * p, rr[c] += r * r;
            }
        }
    }
    std::array<double, 3> k{1, 1, 1};
    for (std::size_t c = 0; c < 3; ++c) {
        if (!(rr[c] > 0 && rp[c] > 0)) return std::nullopt;
        k[c] = std::pow(rp[c] / rr[c], 1.0 / surfel_const::kInvGamma);  // display colour goes as E^(1/2.2)
    }
    return k;
}

}  // namespace lumigauss
