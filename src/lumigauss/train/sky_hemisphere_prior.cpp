#include "lumigauss/train/sky_hemisphere_prior.h"

#include <algorithm>
#include <cmath>

#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/train/sky_losses.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

std::vector<Vec3f> upper_hemisphere_directions(Vec3f up, int count) {
    if (count < 1) throw Error("upper_hemisphere_directions: the count must be at least 1");
    const Vec3f axis = std::abs(up.x) < 0.9f ? Vec3f{1, 0, 0} : Vec3f{0, 1, 0};
    const Vec3f e1 = normalize(cross(up, axis)), e2 = cross(up, e1);
    constexpr double kGoldenAngle = 2.399963229728653;  // pi (3 - sqrt 5)
    std::vector<Vec3f> directions(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
        // Heights uniform in (0, 1): equal solid angle per direction (Archimedes).
        const double z = (i + 0.5) / count, r = std::sqrt(1 - z * z), phi = kGoldenAngle * i;
        directions[std::size_t(i)] =
            float(r * std::cos(phi)) * e1 + float(r * std::sin(phi)) * e2 + float(z) * up;
    }
    return directions;
}

std::vector<Vec3f> directions_out_of_view(std::span<const Vec3f> directions, const Camera& camera) {
    std::vector<Vec3f> out;
    for (const Vec3f& d : directions) {
        const Vec3d c = camera.rotation * d.cast<double>();  // a direction: no translation
        const bool seen = c.z > 0 && [&] {
            const double x = camera.fx * c.x / c.z + camera.cx, y = camera.fy * c.y / c.z + camera.cy;
            return x >= 0 && x <= camera.width && y >= 0 && y <= camera.height;
        }();
        if (!seen) out.push_back(d);
    }
    return out;
}

std::optional<Vec3f> mean_sky_radiance(std::span<const float> photo, std::span<const float> sky_weight,
                                       int min_pixels) {
    if (photo.size() != 3 * sky_weight.size()) throw Error("mean_sky_radiance: the maps differ in size");
    Vec3d sum{};
    int count = 0;
    for (std::size_t p = 0; p < sky_weight.size(); ++p) {
        if (!(sky_weight[p] > 0.5f)) continue;
        const Vec3d colour{photo[3 * p], photo[3 * p + 1], photo[3 * p + 2]};
        if (std::max({colour.x, colour.y, colour.z}) >= kSaturatedPhoto) continue;
        sum += colour;
        ++count;
    }
    if (count < std::max(min_pixels, 1)) return std::nullopt;
    const Vec3d mean = (1.0 / count) * sum;
    const auto linear = [](double v) {
        return float(std::pow(std::max(v, 0.0), 1.0 / surfel_const::kInvGamma));
    };
    return Vec3f{linear(mean.x), linear(mean.y), linear(mean.z)};
}

double sky_hemisphere_prior(std::span<const Vec3f> directions, const ShCoeffs<float>& env,
                            const Sh4Coeffs<float>& residual, Vec3f target, double weight,
                            Sh4Coeffs<float>& g_residual) {
    if (directions.empty()) return 0.0;
    const double scale = 1.0 / (3.0 * double(directions.size()));
    double loss = 0;
    for (const Vec3f& d : directions) {
        const Vec3f error = sky_radiance(env, &residual, d) - target;
        loss += double(dot(error, error)) * scale;
        float y[kSh4Count];
        sh4_basis(d, y);
        const Vec3f g = float(weight * 2 * scale) * error;
        for (int k = 0; k < kSh4Count; ++k) g_residual.c[k] += y[k] * g;
    }
    return loss;
}

}  // namespace lumigauss
