#pragma once
// Eigenvalues and eigenvectors of a symmetric 3x3 matrix by cyclic Jacobi rotations (exact for diagonal
// input): the normal of a point neighbourhood (model/point_normals.h) and the direction every camera's
// x axis is perpendicular to (cameras/up_axis.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "lumigauss/math/vec.h"

namespace lumigauss {

struct SymmetricEigen {
    std::array<double, 3> values{};  // ascending
    std::array<Vec3d, 3> vectors{};  // unit, vectors[i] belongs to values[i]
};

inline SymmetricEigen symmetric_eigen(const Mat3d& symmetric) {
    // Rotate away the largest off-diagonal entry until the matrix is diagonal; the columns of the
    // accumulated rotation are the eigenvectors.
    Mat3d a = symmetric, v = Mat3d::identity();
    for (int sweep = 0; sweep < 32; ++sweep) {
        int p = 0, q = 1;
        for (const auto& [i, j] : {std::pair{0, 2}, std::pair{1, 2}})
            if (std::abs(a(i, j)) > std::abs(a(p, q))) p = i, q = j;
        const double scale = std::abs(a(0, 0)) + std::abs(a(1, 1)) + std::abs(a(2, 2));
        if (!(std::abs(a(p, q)) > 1e-15 * scale)) break;
        const double theta = 0.5 * std::atan2(2 * a(p, q), a(q, q) - a(p, p));
        const double c = std::cos(theta), s = std::sin(theta);
        Mat3d r = Mat3d::identity();
        r(p, p) = c, r(q, q) = c, r(p, q) = s, r(q, p) = -s;
        // a <- r^T a r, v <- v r
        Mat3d ar{}, next{}, vr{};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k) ar(i, j) += a(i, k) * r(k, j), vr(i, j) += v(i, k) * r(k, j);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k) next(i, j) += r(k, i) * ar(k, j);
        a = next, v = vr;
    }
    std::array<int, 3> order{0, 1, 2};
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return a(x, x) < a(y, y); });
    SymmetricEigen out;
    for (int i = 0; i < 3; ++i) {
        const Vec3d e = v.col(order[std::size_t(i)]);
        out.values[std::size_t(i)] = a(order[std::size_t(i)], order[std::size_t(i)]);
        out.vectors[std::size_t(i)] = (1.0 / length(e)) * e;
    }
    return out;
}

// The unit eigenvector of the smallest eigenvalue.
inline Vec3d smallest_eigenvector(const Mat3d& symmetric) {
    return symmetric_eigen(symmetric).vectors[0];
}

}  // namespace lumigauss
