#include "lumigauss/shading/sh4_rotation.h"

#include <array>
#include <cmath>
#include <numbers>

namespace lumigauss {
namespace {

// Gauss-Legendre nodes and weights on [-1, 1], 5 points (exact for polynomials up to degree 9).
constexpr std::array<double, 5> kNodes = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                          0.9061798459386640};
constexpr std::array<double, 5> kWeights = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                            0.4786286704993665, 0.2369268850561891};
constexpr int kAzimuthSteps = 10;  // exact for trigonometric degree <= 9 in the azimuth

}  // namespace

Sh4Coeffs<float> rotate_sh4(const Sh4Coeffs<float>& sh, const Mat3d& rotation) {
    std::array<Vec3d, kSh4Count> sum{};
    const Mat3d inverse = transpose(rotation);
    for (std::size_t i = 0; i < kNodes.size(); ++i) {
        const double z = kNodes[i], r = std::sqrt(1 - z * z);
        const double weight = kWeights[i] * 2 * std::numbers::pi / kAzimuthSteps;  // d(solid angle)
        for (int j = 0; j < kAzimuthSteps; ++j) {
            const double phi = 2 * std::numbers::pi * j / kAzimuthSteps;
            const Vec3d w{r * std::cos(phi), r * std::sin(phi), z};
            double y_old[kSh4Count], y_new[kSh4Count];
            sh4_basis(inverse * w, y_old);  // f'(w) = f(R^T w)
            sh4_basis(w, y_new);
            Vec3d value{};
            for (int k = 0; k < kSh4Count; ++k) value += y_old[k] * sh.c[k].cast<double>();
            for (int k = 0; k < kSh4Count; ++k) sum[std::size_t(k)] += (weight * y_new[k]) * value;
        }
    }
    Sh4Coeffs<float> out;
    for (int k = 0; k < kSh4Count; ++k) out.c[k] = sum[std::size_t(k)].cast<float>();
    return out;
}

}  // namespace lumigauss
