// The Jacobi eigen-solver of math/symmetric_eigen.h at 9 x 9 (the 3 x 3 case is tested with the point
// normals): a matrix built from known eigenpairs gives them back, ascending, with orthonormal vectors, also
// when eigenvalues repeat or vanish (the rank-deficient Gram matrices of eval/light_reference.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumigauss/math/symmetric_eigen.h"

namespace lumigauss {
namespace {

constexpr std::size_t kN = 9;

// A random orthonormal basis (Gram-Schmidt of random vectors), rows.
SquareMatrix<kN> random_rotation(std::mt19937& rng) {
    std::normal_distribution<double> g(0, 1);
    SquareMatrix<kN> q{};
    for (std::size_t i = 0; i < kN; ++i) {
        for (double& x : q[i]) x = g(rng);
        for (std::size_t k = 0; k < i; ++k) {
            double d = 0;
            for (std::size_t j = 0; j < kN; ++j) d += q[i][j] * q[k][j];
            for (std::size_t j = 0; j < kN; ++j) q[i][j] -= d * q[k][j];
        }
        double n = 0;
        for (double x : q[i]) n += x * x;
        for (double& x : q[i]) x /= std::sqrt(n);
    }
    return q;
}

void expect_eigenpairs(const std::array<double, kN>& values, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const SquareMatrix<kN> q = random_rotation(rng);
    SquareMatrix<kN> a{};
    for (std::size_t i = 0; i < kN; ++i)
        for (std::size_t j = 0; j < kN; ++j)
            for (std::size_t k = 0; k < kN; ++k) a[i][j] += q[k][i] * values[k] * q[k][j];
    const SymmetricEigenN<kN> e = symmetric_eigen<kN>(a);
    std::array<double, kN> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < kN; ++i) {
        EXPECT_NEAR(e.values[i], sorted[i], 1e-10) << i;
        for (std::size_t r = 0; r < kN; ++r) {
            double av = 0;
            for (std::size_t k = 0; k < kN; ++k) av += a[r][k] * e.vectors[i][k];
            EXPECT_NEAR(av, e.values[i] * e.vectors[i][r], 1e-9) << i << " " << r;
        }
        for (std::size_t j = 0; j < kN; ++j) {
            double d = 0;
            for (std::size_t k = 0; k < kN; ++k) d += e.vectors[i][k] * e.vectors[j][k];
            EXPECT_NEAR(d, i == j ? 1.0 : 0.0, 1e-10) << i << " " << j;
        }
    }
}

TEST(SymmetricEigen, NineByNineGivesBackItsEigenpairsInAscendingOrder) {
    expect_eigenpairs({5, -2, 0.5, 3, 1e-3, 7, -0.25, 2, 4}, 1);
}

TEST(SymmetricEigen, RepeatedAndZeroEigenvaluesKeepAnOrthonormalBasis) {
    expect_eigenpairs({0, 0, 0, 1, 1, 2, 2, 2, 9}, 2);
}

TEST(SymmetricEigen, DiagonalInputIsExact) {
    SquareMatrix<kN> a{};
    for (std::size_t i = 0; i < kN; ++i) a[i][i] = double(kN - i);
    const SymmetricEigenN<kN> e = symmetric_eigen<kN>(a);
    for (std::size_t i = 0; i < kN; ++i) {
        EXPECT_EQ(e.values[i], double(i + 1));
        EXPECT_EQ(std::abs(e.vectors[i][kN - 1 - i]), 1.0);
    }
}

}  // namespace
}  // namespace lumigauss
