#include "lumigauss/model/point_normals.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lumigauss/model/knn.h"

namespace lumigauss {

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
