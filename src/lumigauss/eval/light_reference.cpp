#include "lumigauss/eval/light_reference.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "lumigauss/eval/light_scale.h"
#include "lumigauss/io/image.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace fs = std::filesystem;

namespace {

using ShVector = std::array<double, kShCount>;
using ShMatrix = SquareMatrix<kShCount>;

// A direction's share of the largest Gram eigenvalue below which the normals do not tell it apart. The
// spectrum has no clean gap on real scenes (columns, slanted roofs: plaza's smallest shares are 1e-3.3 to
// 1e-4.3), so this is a choice: the weak directions shade a pixel ~3 % as much as the strongest one per unit
// of light, less than shadows, interreflections and the degree-2 truncation disturb the shading. On plaza the
// reference's whole-light residual is lowest here (1e-2: 0.56, 1e-3: 0.50, 1e-4: 0.58, every direction
// fitted: 0.59; bench/RESULTS.md, session 42).
constexpr double kSeenEigenShare = 1e-3;
// A sample below this share of the unshadowed fit is taken for a cast shadow.
constexpr double kShadowShare = 0.6;
constexpr int kShadowRefits = 4;

ShVector lobe(const Vec3d& normal) {
    ShVector w{};
    cosine_lobe_sh(normal, w.data());
    return w;
}

// The orthogonal projector onto the eigenvectors of `gram` whose eigenvalue is at least `share` of the
// largest, and their count.
ShMatrix dominant_projector(const ShMatrix& gram, double share, int& count) {
    const SymmetricEigenN<kShCount> e = symmetric_eigen<kShCount>(gram);
    const double largest = e.values[kShCount - 1];
    ShMatrix p{};
    count = 0;
    for (std::size_t k = 0; k < kShCount; ++k) {
        if (!(largest > 0) || e.values[k] < share * largest) continue;
        ++count;
        for (std::size_t i = 0; i < kShCount; ++i)
            for (std::size_t j = 0; j < kShCount; ++j) p[i][j] += e.vectors[k][i] * e.vectors[k][j];
    }
    return p;
}

ShVector multiply(const ShMatrix& m, const ShVector& x) {
    ShVector y{};
    for (std::size_t i = 0; i < kShCount; ++i)
        for (std::size_t j = 0; j < kShCount; ++j) y[i] += m[i][j] * x[j];
    return y;
}

// argmin over L in the range of `seen` of sum (x.L - y)^2, from the normal equations projected on it:
// the pseudo-inverse of P G P (its null space is the unseen part) times P b.
ShVector solve_on(const ShMatrix& seen, const ShMatrix& gram, const ShVector& rhs) {
    ShMatrix pgp{};
    for (std::size_t i = 0; i < kShCount; ++i)
        for (std::size_t j = 0; j < kShCount; ++j)
            for (std::size_t k = 0; k < kShCount; ++k)
                for (std::size_t l = 0; l < kShCount; ++l) pgp[i][j] += seen[i][k] * gram[k][l] * seen[l][j];
    const SymmetricEigenN<kShCount> e = symmetric_eigen<kShCount>(pgp);
    const ShVector b = multiply(seen, rhs);
    ShVector x{};
    const double largest = e.values[kShCount - 1];
    for (std::size_t k = 0; k < kShCount; ++k) {
        if (!(largest > 0) || e.values[k] < 1e-9 * largest) continue;
        double vb = 0;
        for (std::size_t i = 0; i < kShCount; ++i) vb += e.vectors[k][i] * b[i];
        for (std::size_t i = 0; i < kShCount; ++i) x[i] += e.vectors[k][i] * vb / e.values[k];
    }
    return x;
}

// One channel's light: least squares of radiance = albedo / pi * E(n) on the seen part, refitted without the
// samples the previous fit finds in shadow.
ShVector fit_channel(const std::vector<ShadingSample>& samples, const std::vector<ShVector>& lobes,
                     const ShMatrix& seen, int c) {
    std::vector<bool> lit(samples.size(), true);
    ShVector light{};
    for (int pass = 0; pass <= kShadowRefits; ++pass) {
        ShMatrix gram{};
        ShVector rhs{};
        for (std::size_t s = 0; s < samples.size(); ++s) {
            if (!lit[s]) continue;
            const double a = samples[s].albedo[c] / std::numbers::pi, y = samples[s].radiance[c];
            for (std::size_t i = 0; i < kShCount; ++i) {
                rhs[i] += a * lobes[s][i] * y;
                for (std::size_t j = 0; j < kShCount; ++j) gram[i][j] += a * a * lobes[s][i] * lobes[s][j];
            }
        }
        light = solve_on(seen, gram, rhs);
        for (std::size_t s = 0; s < samples.size(); ++s) {
            double predicted = 0;
            for (std::size_t i = 0; i < kShCount; ++i) predicted += lobes[s][i] * light[i];
            predicted *= samples[s].albedo[c] / std::numbers::pi;
            lit[s] = samples[s].radiance[c] > kShadowShare * predicted;
        }
    }
    return light;
}

ShVector channel(const ShCoeffs<double>& sh, int c) {
    ShVector v{};
    for (std::size_t j = 0; j < kShCount; ++j) v[j] = sh.c[j][c];
    return v;
}

// The usable pixels of one training photo (header), nothing when it has no gt/albedo or gt/normal.
std::vector<ShadingSample> photo_samples(const GtSceneMeta& meta, const Dataset& scene, const View& view) {
    const std::string albedo_path = gt_image_path(meta.root, "albedo", view.name);
    const std::string normal_path = gt_image_path(meta.root, "normal", view.name);
    if (!fs::exists(albedo_path) || !fs::exists(normal_path)) return {};
    const Image photo = scene.load_image(view);
    bool has_gt_mask = false;
    const Image mask = evaluation_mask(meta, scene, view, has_gt_mask);
    const Image albedo = load_gt_image(albedo_path, photo.width, photo.height, 3);
    const Image normal = load_gt_image(normal_path, photo.width, photo.height, 3);
    std::vector<ShadingSample> samples;
    for (std::size_t q = 0; q < mask.pixels.size(); ++q) {
        if (!(mask.pixels[q] > 0.5f)) continue;
        ShadingSample s;
        bool usable = true;
        for (std::size_t c = 0; c < 3; ++c) {
            const float p = photo.pixels[3 * q + c];
            usable = usable && p < 0.99f && albedo.pixels[3 * q + c] >= 0.02f;
            s.radiance[int(c)] = srgb_to_linear(p);
            s.albedo[int(c)] = albedo.pixels[3 * q + c];
            s.normal[int(c)] = 2.0 * normal.pixels[3 * q + c] - 1.0;
        }
        const double n = length(s.normal);
        if (!usable || !(n > 0.5)) continue;
        s.normal = (1.0 / n) * s.normal;
        samples.push_back(s);
    }
    return samples;
}

double weighted_norm2(const ShCoeffs<double>& sh) {
    double sum = 0;
    for (int j = 0; j < kShCount; ++j)
        for (int c = 0; c < 3; ++c) sum += irradiance_weight(j) * sh.c[j][c] * sh.c[j][c];
    return sum;
}

}  // namespace

ShCoeffs<double> project_light(const ShMatrix& projector, const ShCoeffs<double>& light) {
    ShCoeffs<double> out;
    for (int c = 0; c < 3; ++c) {
        const ShVector v = multiply(projector, channel(light, c));
        for (std::size_t j = 0; j < kShCount; ++j) out.c[j][c] = v[j];
    }
    return out;
}

PhotoLightReference fit_photo_light_reference(const std::vector<ShadingSample>& samples) {
    if (samples.empty()) throw Error("light reference: no usable pixel to fit a light to");
    std::vector<ShVector> lobes;
    lobes.reserve(samples.size());
    ShMatrix gram{};
    for (const ShadingSample& s : samples) {
        lobes.push_back(lobe(s.normal));
        for (std::size_t i = 0; i < kShCount; ++i)
            for (std::size_t j = 0; j < kShCount; ++j) gram[i][j] += lobes.back()[i] * lobes.back()[j];
    }
    PhotoLightReference ref;
    ref.seen = dominant_projector(gram, kSeenEigenShare, ref.seen_count);
    for (int c = 0; c < 3; ++c) {
        const ShVector l = fit_channel(samples, lobes, ref.seen, c);
        for (std::size_t j = 0; j < kShCount; ++j) ref.light.c[j][c] = l[j];
    }
    return ref;
}

std::optional<LightReference> light_reference(const RelightableRun& run, const Dataset& scene,
                                              const GtSceneMeta& meta,
                                              const std::vector<std::string>& exclude) {
    std::vector<ShCoeffs<double>> reference, reference_seen, learned_seen, truth, truth_seen;
    std::vector<double> exposure;
    std::vector<int> seen_counts;
    double unseen = 0, whole = 0;
    for (std::size_t i = 0; i < run.image_names.size(); ++i) {
        const GtImageMeta* m = meta.find(run.image_names[i]);
        if (!m || m->split != "train") continue;
        if (std::find(exclude.begin(), exclude.end(), m->name) != exclude.end()) continue;
        const auto view = std::find_if(scene.views.begin(), scene.views.end(),
                                       [&](const View& v) { return v.name == m->name; });
        if (view == scene.views.end()) continue;
        const std::vector<ShadingSample> samples = photo_samples(meta, scene, *view);
        if (samples.empty()) continue;
        const PhotoLightReference ref = fit_photo_light_reference(samples);
        const ShCoeffs<double> t = load_condition_sh(meta, m->condition);
        const ShCoeffs<double> t_seen = project_light(ref.seen, t);
        ShCoeffs<double> t_unseen;
        for (int j = 0; j < kShCount; ++j) t_unseen.c[j] = t.c[j] - t_seen.c[j];
        unseen += m->exposure * m->exposure * weighted_norm2(t_unseen);
        whole += m->exposure * m->exposure * weighted_norm2(t);
        reference.push_back(ref.light);
        reference_seen.push_back(project_light(ref.seen, ref.light));
        learned_seen.push_back(project_light(ref.seen, run.learned_sh[i]));
        truth.push_back(t);
        truth_seen.push_back(t_seen);
        exposure.push_back(m->exposure);
        seen_counts.push_back(ref.seen_count);
    }
    if (reference.empty() || !(whole > 0)) return std::nullopt;
    LightReference out;
    out.photos = int(reference.size());
    std::sort(seen_counts.begin(), seen_counts.end());
    out.min_seen = seen_counts.front();
    out.median_seen = seen_counts[seen_counts.size() / 2];
    out.unseen_share = std::sqrt(unseen / whole);
    out.reference_residual = fit_light_scale(reference, truth, exposure).relative_residual;
    out.reference_seen_residual = fit_light_scale(reference_seen, truth_seen, exposure).relative_residual;
    out.learned_seen_residual = fit_light_scale(learned_seen, truth_seen, exposure).relative_residual;
    return out;
}

}  // namespace lumigauss
