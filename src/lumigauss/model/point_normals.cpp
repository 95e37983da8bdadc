#include "lumigauss/model/point_normals.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lumigauss/model/knn.h"

namespace lumigauss {

Vec3d smallest_eigenvector(const Mat3d& symmetric) {
    // Cyclic Jacobi: rotate away the largest off-diagonal entry until the matrix is diagonal; the columns of
    // the accumulated rotation are the eigenvectors.
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
    int smallest = 0;
    for (int i = 1; i < 3; ++i)
        if (a(i, i) < a(smallest, smallest)) smallest = i;
    const Vec3d e = v.col(smallest);
    return (1.0 / length(e)) * e;
}

Vec4<double> quaternion_with_normal(Vec3d n) {
    // The shortest rotation taking +z to n: axis z x n, half-angle from 1 + z.n.
    const double w = 1.0 + n.z;
    if (w < 1e-9) return {0.0, 1.0, 0.0, 0.0};  // n = -z: half a turn about x
    const Vec4<double> q{w, -n.y, n.x, 0.0};    // (w, z x n)
    const double inv = 1.0 / std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    return {q.x * inv, q.y * inv, q.z * inv, q.w * inv};
}

std::vector<Vec3f> point_normals(const std::vector<Vec3f>& points, int k) {
    std::vector<Vec3f> normals(points.size(), Vec3f{0, 0, 1});
    if (points.size() < 3) return normals;
    k = std::clamp(k, 2, 16);
    const std::vector<std::uint32_t> neighbours = knn_indices(points, k);
    for (std::size_t i = 0; i < points.size(); ++i) {
        Vec3d mean = points[i].cast<double>();
        for (int j = 0; j < k; ++j)
            mean += points[neighbours[i * std::size_t(k) + std::size_t(j)]].cast<double>();
        mean = (1.0 / (k + 1)) * mean;
        Mat3d cov{};
        const auto add = [&](const Vec3f& p) {
            const Vec3d e = p.cast<double>() - mean;
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) cov(r, c) += e[r] * e[c];
        };
        add(points[i]);
        for (int j = 0; j < k; ++j) add(points[neighbours[i * std::size_t(k) + std::size_t(j)]]);
        normals[i] = smallest_eigenvector(cov).cast<float>();
    }
    return normals;
}

}  // namespace lumigauss
