#include "lumigauss/eval/relightable_run.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

constexpr double kGamma = 1.0 / surfel_const::kInvGamma;  // 2.2, the model's light-to-colour exponent

}  // namespace

RelightableRun load_relightable_run(const std::string& path) {
    TrainedRun trained = load_run_or_ply(path);
    RelightableRun run;
    run.dir = trained.dir;
    run.model = std::move(trained.model);
    run.image_names = std::move(trained.image_names);
    for (int i = 0; i < trained.lighting.num_images(); ++i) run.learned_sh.push_back(trained.learned_sh(i));
    run.downscale = trained.downscale;
    run.sky_background = trained.sky_background;
    run.sky_horizon = trained.sky_horizon;
    run.side_rule = trained.side_rule;
    return run;
}

SurfelModel relightable_from_surfels(const ViewDependentSurfels& s) {
    const std::size_t n = s.size();
    const std::size_t coeffs = std::size_t((s.sh_degree + 1) * (s.sh_degree + 1));
    if (s.sh.size() != n * coeffs * 3) throw Error("relightable_from_surfels: SH array of the wrong size");
    std::vector<std::vector<float>> raw(kModelParamCount);
    raw[int(ModelParam::Xyz)] = s.surfels.means;
    raw[int(ModelParam::Rotation)] = s.surfels.quats;
    for (float v : s.surfels.scales) raw[int(ModelParam::Scaling)].push_back(std::log(std::max(v, 1e-12f)));
    for (float v : s.surfels.opacities)
        raw[int(ModelParam::Opacity)].push_back(inverse_sigmoid(std::clamp(v, 1e-6f, 1.0f - 1e-6f)));
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t c = 0; c < 3; ++c) {
            const double rho = std::max(0.0, 0.5 + sh_const::kY00 * double(s.sh[i * coeffs * 3 + c]));
            const double target = std::pow(rho / std::numbers::pi, 1.0 / kGamma);
            raw[int(ModelParam::Albedo)].push_back(float((target - 0.5) / sh_const::kY00));
        }
        const Vec4f q = normalize_quaternion(Vec4f{s.surfels.quats[4 * i], s.surfels.quats[4 * i + 1],
                                                   s.surfels.quats[4 * i + 2], s.surfels.quats[4 * i + 3]});
        const Mat3f r = rotation_from_unit_quaternion(q);
        const Vec3f axis{r.m[0][2], r.m[1][2], r.m[2][2]};
        float pos[kShCount], neg[kShCount];
        cosine_lobe_sh(axis, pos);
        cosine_lobe_sh(-axis, neg);
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) {
                raw[int(ModelParam::TransferPositive)].push_back(pos[k]);
                raw[int(ModelParam::TransferNegative)].push_back(neg[k]);
            }
    }
    return SurfelModel::from_raw(std::move(raw));
}

}  // namespace lumigauss
