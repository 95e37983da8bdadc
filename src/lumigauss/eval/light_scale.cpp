#include "lumigauss/eval/light_scale.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "lumigauss/relight/relit_render.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

double irradiance_weight(int j) {
    const double a = j == 0 ? rh_const::kA0 : (j < 4 ? rh_const::kA1 : rh_const::kA2);
    return a * a;
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
    }
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
    RelitRenderer renderer(run.model, backend);
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
