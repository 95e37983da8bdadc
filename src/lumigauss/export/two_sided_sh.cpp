#include "lumigauss/export/two_sided_sh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <numbers>
#include <string>

#include "lumigauss/model/view_sh.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

StepExpansion step_expansion(int degree) {
    if (degree >= 3) return {1.44, -0.64};
    if (degree >= 1) return {4.0 / 3.0, 0.0};
    return {};
}

std::vector<float> two_sided_view_sh(const SurfelModel& model, const SurfelSides& sides, int degree,
                                     std::span<const Vec3d> cameras) {
    if (degree < 0 || degree > 3) throw Error("SH degree " + std::to_string(degree) + ": use 0, 1, 2 or 3");
    const std::size_t n = model.size();
    if (sides.positive.size() != 3 * n || sides.negative.size() != 3 * n)
        throw Error("two_sided_view_sh: the baked sides do not match the model");
    const std::size_t count = std::size_t(view_sh_coefficients(degree));
    std::vector<float> sh(n * count * 3, 0.0f);
    const double y00 = sh_const::kY00;
    if (degree == 0) {
        const std::vector<float> seen = seen_side_colours(model, sides, cameras);
        for (std::size_t v = 0; v < 3 * n; ++v) sh[v] = float((seen[v] - 0.5) / y00);
        return sh;
    }
    const StepExpansion step = step_expansion(degree);
    // -c_l 4 pi / (2l + 1) for l = 1, 2, 3.
    const double band[4] = {0, -step.c1 * 4 * std::numbers::pi / 3, 0, -step.c3 * 4 * std::numbers::pi / 7};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            double basis[16];
            view_sh_basis(degree, model.normal(i).cast<double>(), basis);
            float* out = &sh[i * count * 3];
            for (int c = 0; c < 3; ++c) {
                const double pos = sides.positive[3 * i + std::size_t(c)];
                const double neg = sides.negative[3 * i + std::size_t(c)];
                const double mean = 0.5 * (pos + neg), half = 0.5 * (pos - neg);
                out[c] = float((mean - 0.5) / y00);
                for (std::size_t k = 1; k < count; ++k) {
                    const int l = k < 4 ? 1 : (k < 9 ? 2 : 3);
                    out[3 * k + std::size_t(c)] = float(band[l] * basis[k] * half);
                }
            }
        }
    });
    return sh;
}

void check_view_sh_size(std::size_t values, std::size_t surfels, int degree) {
    if (degree < 0 || degree > 3) throw Error("SH degree " + std::to_string(degree) + " is not 0..3");
    const std::size_t expected = 3 * std::size_t(view_sh_coefficients(degree)) * surfels;
    if (values != expected)
        throw Error(std::to_string(values) + " SH values for " + std::to_string(surfels) +
                    " surfels of degree " + std::to_string(degree) + " (" + std::to_string(expected) +
                    " expected)");
}

}  // namespace lumigauss
