#include "lumigauss/model/ground_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "lumigauss/shading/surfel_shading.h"

namespace lumigauss {
namespace {

// The weighted median by a histogram: training asks for it every iteration, and a sort of every surfel
// would cost a few per cent of one. Bins of 1/1024 over [0, 2] (albedos above 2 fall in the last one).
constexpr int kBins = 2048;
constexpr float kTop = 2.0f;

struct Histogram {
    std::vector<double> weight = std::vector<double>(kBins, 0.0);

    void add(float value, double w) {
        const int bin = std::clamp(int(value / kTop * float(kBins)), 0, kBins - 1);
        weight[std::size_t(bin)] += w;
    }
    // The value where the cumulative weight crosses half the total, linear inside its bin.
    float median(double total) const {
        double below = 0;
        for (int b = 0; b < kBins; ++b) {
            const double w = weight[std::size_t(b)];
            if (below + w >= 0.5 * total) {
                const double inside = w > 0 ? (0.5 * total - below) / w : 0.0;
                return float((double(b) + inside) / kBins * double(kTop));
            }
            below += w;
        }
        return kTop;
    }
};

}  // namespace

Vec3f ground_albedo(const SurfelModel& model, Vec3f up) {
    const float up_length = length(up);
    if (!(up_length > 0)) return {};
    up = (1.0f / up_length) * up;
    const float facing = float(std::cos(30.0 * std::numbers::pi / 180.0));
    const std::vector<float>& scales = model.param(ModelParam::Scaling);
    const std::vector<float>& opacities = model.param(ModelParam::Opacity);
    std::array<Histogram, 3> channels;
    double total = 0;
    for (std::size_t i = 0; i < model.size(); ++i) {
        if (!(std::abs(dot(model.normal(i), up)) >= facing)) continue;
        const double weight =
            double(sigmoid(opacities[i])) * std::exp(double(scales[2 * i]) + double(scales[2 * i + 1]));
        const Vec3f albedo = albedo_activation(model.raw_albedo(i));
        // A NaN albedo (a diverged surfel, which the training's finite check reports) has no bin.
        if (!(weight > 0) || !std::isfinite(weight) || !std::isfinite(albedo.x + albedo.y + albedo.z))
            continue;
        for (int c = 0; c < 3; ++c) channels[std::size_t(c)].add(albedo[c], weight);
        total += weight;
    }
    if (!(total > 0)) return {};
    return {channels[0].median(total), channels[1].median(total), channels[2].median(total)};
}

}  // namespace lumigauss
