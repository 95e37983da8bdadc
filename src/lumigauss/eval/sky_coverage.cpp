#include "lumigauss/eval/sky_coverage.h"

#include "lumigauss/util/error.h"

namespace lumigauss {

SkyCoverage sky_coverage(const Image& mask, std::span<const float> alpha) {
    if (mask.channels != 1 || mask.pixels.size() != alpha.size())
        throw Error("sky_coverage: the mask and the alpha map differ in size");
    SkyCoverage s;
    std::size_t covered = 0;
    double alpha_sum = 0;
    for (std::size_t q = 0; q < alpha.size(); ++q) {
        if (mask.pixels[q] != 0.0f) continue;
        ++s.pixels;
        covered += alpha[q] > 0.5f ? 1 : 0;
        alpha_sum += alpha[q];
    }
    if (s.pixels > 0) {
        s.covered = double(covered) / double(s.pixels);
        s.mean_alpha = alpha_sum / double(s.pixels);
    }
    return s;
}

}  // namespace lumigauss
