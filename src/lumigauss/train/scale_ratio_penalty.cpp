#include "lumigauss/train/scale_ratio_penalty.h"

#include <cmath>

#include "lumigauss/util/error.h"

namespace lumigauss {

double scale_ratio_penalty(std::span<const float> scales, double max_ratio, double weight,
                           std::span<float> grad_scales) {
    if (scales.size() % 2 != 0 || grad_scales.size() != scales.size())
        throw Error("scale_ratio_penalty: scales and gradients must hold 2 values per surfel");
    const std::size_t n = scales.size() / 2;
    if (n == 0) return 0.0;
    const double log_limit = std::log(max_ratio);
    const double g_each = weight / double(n);
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double su = scales[2 * i], sv = scales[2 * i + 1];
        const double excess = std::abs(std::log(su) - std::log(sv)) - log_limit;
        if (!(excess > 0)) continue;
        sum += excess;
        // d|log su - log sv| / d su = sign / su, and the opposite for sv.
        const double sign = su > sv ? 1.0 : -1.0;
        grad_scales[2 * i] += float(g_each * sign / su);
        grad_scales[2 * i + 1] -= float(g_each * sign / sv);
    }
    return sum / double(n);
}

}  // namespace lumigauss
