#pragma once
// Eigenvalues and eigenvectors of a small symmetric matrix by cyclic Jacobi rotations (exact for diagonal
// input): the normal of a point neighbourhood (model/point_normals.h), the direction every camera's x axis is
// perpendicular to (cameras/up_axis.h), and the lights a photo's normals can tell apart
// (eval/light_reference.h, 9 x 9).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "lumigauss/math/vec.h"

namespace lumigauss {

template <std::size_t N>
using SquareMatrix = std::array<std::array<double, N>, N>;

template <std::size_t N>
struct SymmetricEigenN {
    std::array<double, N> values{};                  // ascending
    std::array<std::array<double, N>, N> vectors{};  // unit, vectors[i] belongs to values[i]
};

template <std::size_t N>
SymmetricEigenN<N> symmetric_eigen(const SquareMatrix<N>& symmetric) {
    // Rotate away the largest off-diagonal entry until the matrix is diagonal; the columns of the
    // accumulated rotation are the eigenvectors.
    SquareMatrix<N> a = symmetric, v{};
    for (std::size_t i = 0; i < N; ++i) v[i][i] = 1;
    for (std::size_t sweep = 0; sweep < 32 * N * (N - 1) / 6; ++sweep) {
        std::size_t p = 0, q = 1;
        for (std::size_t i = 0; i < N; ++i)
            for (std::size_t j = i + 1; j < N; ++j)
                if (std::abs(a[i][j]) > std::abs(a[p][q])) p = i, q = j;
        double scale = 0;
        for (std::size_t i = 0; i < N; ++i) scale += std::abs(a[i][i]);
        if (!(std::abs(a[p][q]) > 1e-15 * scale)) break;
        const double theta = 0.5 * std::atan2(2 * a[p][q], a[q][q] - a[p][p]);
        const double c = std::cos(theta), s = std::sin(theta);
        SquareMatrix<N> r{};
        for (std::size_t i = 0; i < N; ++i) r[i][i] = 1;
        r[p][p] = c, r[q][q] = c, r[p][q] = s, r[q][p] = -s;
        // a <- r^T a r, v <- v r
        SquareMatrix<N> ar{}, next{}, vr{};
        for (std::size_t i = 0; i < N; ++i)
            for (std::size_t j = 0; j < N; ++j)
                for (std::size_t k = 0; k < N; ++k)
                    ar[i][j] += a[i][k] * r[k][j], vr[i][j] += v[i][k] * r[k][j];
        for (std::size_t i = 0; i < N; ++i)
            for (std::size_t j = 0; j < N; ++j)
                for (std::size_t k = 0; k < N; ++k) next[i][j] += r[k][i] * ar[k][j];
        a = next, v = vr;
    }
    std::array<std::size_t, N> order{};
    for (std::size_t i = 0; i < N; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t x, std::size_t y) { return a[x][x] < a[y][y]; });
    SymmetricEigenN<N> out;
    for (std::size_t i = 0; i < N; ++i) {
        double norm = 0;
        for (std::size_t k = 0; k < N; ++k) norm += v[k][order[i]] * v[k][order[i]];
        const double inverse_length = 1.0 / std::sqrt(norm);
        out.values[i] = a[order[i]][order[i]];
        for (std::size_t k = 0; k < N; ++k) out.vectors[i][k] = inverse_length * v[k][order[i]];
    }
    return out;
}

struct SymmetricEigen {
    std::array<double, 3> values{};  // ascending
    std::array<Vec3d, 3> vectors{};  // unit, vectors[i] belongs to values[i]
};

inline SymmetricEigen symmetric_eigen(const Mat3d& symmetric) {
    SquareMatrix<3> m{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m[std::size_t(i)][std::size_t(j)] = symmetric(i, j);
    const SymmetricEigenN<3> e = symmetric_eigen<3>(m);
    SymmetricEigen out;
    for (std::size_t i = 0; i < 3; ++i)
        out.values[i] = e.values[i], out.vectors[i] = {e.vectors[i][0], e.vectors[i][1], e.vectors[i][2]};
    return out;
}

// The unit eigenvector of the smallest eigenvalue.
inline Vec3d smallest_eigenvector(const Mat3d& symmetric) {
    return symmetric_eigen(symmetric).vectors[0];
}

}  // namespace lumigauss
