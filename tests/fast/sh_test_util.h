#pragma once
// Shared helpers of the Sh* tests: seeded random inputs and central finite differences in double.
#include <cmath>
#include <random>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss::sh_test {

inline double uniform(std::mt19937_64& rng, double lo = -1.0, double hi = 1.0) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline Vec3d random_vec(std::mt19937_64& rng) {
    return {uniform(rng), uniform(rng), uniform(rng)};
}

inline Vec3d random_unit(std::mt19937_64& rng) {
    for (;;) {
        const Vec3d v = random_vec(rng);
        const double len = length(v);
        if (len > 0.1 && len <= 1.0) return v / len;  // rejection sampling keeps it uniform on the sphere
    }
}

inline ShCoeffs<double> random_sh(std::mt19937_64& rng) {
    ShCoeffs<double> sh;
    for (Vec3d& c : sh.c) c = random_vec(rng);
    return sh;
}

inline Mat3d random_rotation(std::mt19937_64& rng) {
    const Vec4<double> q{uniform(rng), uniform(rng), uniform(rng), uniform(rng)};
    return rotation_from_unit_quaternion(normalize_quaternion(q));
}

inline double max_abs_diff(const ShCoeffs<double>& a, const ShCoeffs<double>& b) {
    double m = 0;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) m = std::fmax(m, std::fabs(a.c[k][c] - b.c[k][c]));
    return m;
}

inline double max_abs(const ShCoeffs<double>& a) {
    return max_abs_diff(a, ShCoeffs<double>{});
}

// Central-difference gradient of a scalar function of a Vec3d.
template <typename F>
Vec3d fd_gradient(F&& f, Vec3d x, double eps = 1e-6) {
    Vec3d g;
    for (int i = 0; i < 3; ++i) {
        Vec3d hi = x, lo = x;
        hi[i] += eps;
        lo[i] -= eps;
        g[i] = (f(hi) - f(lo)) / (2 * eps);
    }
    return g;
}

// Central-difference gradient of a scalar function of SH coefficients.
template <typename F>
ShCoeffs<double> fd_gradient_sh(F&& f, const ShCoeffs<double>& x, double eps = 1e-6) {
    ShCoeffs<double> g;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) {
            ShCoeffs<double> hi = x, lo = x;
            hi.c[k][c] += eps;
            lo.c[k][c] -= eps;
            g.c[k][c] = (f(hi) - f(lo)) / (2 * eps);
        }
    return g;
}

}  // namespace lumigauss::sh_test
