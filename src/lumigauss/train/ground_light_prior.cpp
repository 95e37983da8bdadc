#include "lumigauss/train/ground_light_prior.h"

#include <cmath>
#include <initializer_list>
#include <numbers>

#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/surfel_shading.h"

namespace lumigauss {

void ground_light_directions(Vec3d up, Vec3d out[kGroundLightDirections]) {
    // Any unit vector across `up` starts the rings; the prior does not depend on which.
    const Vec3d helper = std::abs(up.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    const Vec3d e1 = normalize(cross(up, helper)), e2 = cross(up, e1);
    out[0] = -up;
    int k = 1;
    for (const double below_deg : {30.0, 60.0}) {
        const double elevation = -below_deg * std::numbers::pi / 180.0;
        for (int i = 0; i < 8; ++i) {
            const double azimuth = 2.0 * std::numbers::pi * i / 8.0;
            out[k++] = std::cos(elevation) * (std::cos(azimuth) * e1 + std::sin(azimuth) * e2) +
                       std::sin(elevation) * up;
        }
    }
}

Vec3d ground_reflectance(Vec3f ground_albedo, double assumed_albedo) {
    Vec3d linear;
    for (int c = 0; c < 3; ++c)
        linear[c] = std::pow(std::max(0.0, double(ground_albedo[c])), 1.0 / surfel_const::kInvGamma);
    if (assumed_albedo <= 0) return linear;
    const double mean = (linear.x + linear.y + linear.z) / 3.0;
    const Vec3d colour = mean > 0 ? linear / mean : Vec3d{1, 1, 1};
    return colour * (assumed_albedo / std::numbers::pi);
}

double ground_light_prior(const ShCoeffs<float>& env, Vec3f up, Vec3d reflectance, double weight,
                          ShCoeffs<float>& g_env) {
    if (!(reflectance.x > 0 || reflectance.y > 0 || reflectance.z > 0)) return 0.0;
    const ShCoeffs<double> sh = env.cast<double>();
    const Vec3d u = up.cast<double>();
    const Vec3d target = hadamard(reflectance, irradiance(sh, u));
    Vec3d dirs[kGroundLightDirections];
    ground_light_directions(u, dirs);
    const double norm = 1.0 / (3.0 * kGroundLightDirections);
    double loss = 0;
    ShCoeffs<double> g{};
    for (const Vec3d& d : dirs) {
        const Vec3d diff = eval_sh(sh, d) - target;
        loss += dot(diff, diff) * norm;
        eval_sh_vjp_coeffs(d, diff * (2.0 * weight * norm), g);
    }
    if (weight != 0)
        for (int k = 0; k < kShCount; ++k) g_env.c[k] = g_env.c[k] + g.c[k].cast<float>();
    return loss;
}

}  // namespace lumigauss
