#include "lumigauss/model/knn.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace lumigauss {

namespace {

struct Grid {
    Vec3d lo{};
    double cell = 1;
    std::array<int, 3> dims{1, 1, 1};
    std::vector<std::uint32_t> start;  // per cell: first index into `order`; size cells + 1
    std::vector<std::uint32_t> order;  // point indices sorted by cell

    int coord(double v, int axis) const {
        // Clamp in double first: a far outlier would overflow the int conversion.
        const double c = std::floor((v - lo[axis]) / cell);
        return int(std::clamp(c, 0.0, double(dims[std::size_t(axis)] - 1)));
    }
    std::size_t index(int x, int y, int z) const {
        return (std::size_t(z) * std::size_t(dims[1]) + std::size_t(y)) * std::size_t(dims[0]) +
               std::size_t(x);
    }
};

// Per-axis bounds of the bulk of the cloud: the 0.5 and 99.5 percentiles, so that a few far SfM outliers do
// not stretch the cells until everything shares one. Points outside are clamped into the border cells,
// which keeps the search bound valid (they are only farther from the unvisited cells than their cell is).
void robust_bounds(const std::vector<Vec3f>& points, Vec3d& lo, Vec3d& hi) {
    const std::size_t n = points.size();
    const std::size_t cut = n >= 200 ? n / 200 : 0;
    std::vector<float> axis(n);
    for (int a = 0; a < 3; ++a) {
        for (std::size_t i = 0; i < n; ++i) axis[i] = points[i][a];
        std::nth_element(axis.begin(), axis.begin() + std::ptrdiff_t(cut), axis.end());
        lo[a] = axis[cut];
        std::nth_element(axis.begin(), axis.begin() + std::ptrdiff_t(n - 1 - cut), axis.end());
        hi[a] = axis[n - 1 - cut];
    }
}

// About two points per cell over the bounds, capped so that flat or line-like clouds do not allocate a huge
// number of empty cells.
Grid build_grid(const std::vector<Vec3f>& points) {
    Grid g;
    Vec3d lo{}, hi{};
    robust_bounds(points, lo, hi);
    const double ex = hi[0] - lo[0], ey = hi[1] - lo[1], ez = hi[2] - lo[2];
    const double extent = std::max({ex, ey, ez, 1e-12});
    const double target_cells = std::max(1.0, double(points.size()) / 2.0);
    // Cell edge from the volume, but never finer than extent / 2^10 per axis.
    const double volume =
        std::max(ex, extent * 1e-3) * std::max(ey, extent * 1e-3) * std::max(ez, extent * 1e-3);
    g.cell = std::max(std::cbrt(volume / target_cells), extent / 1024.0);
    g.lo = lo;
    for (int a = 0; a < 3; ++a)
        g.dims[std::size_t(a)] = std::max(1, int(std::floor((hi[a] - lo[a]) / g.cell)) + 1);
    const std::size_t cells = std::size_t(g.dims[0]) * std::size_t(g.dims[1]) * std::size_t(g.dims[2]);
    std::vector<std::size_t> cell_of(points.size());
    g.start.assign(cells + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Vec3f& p = points[i];
        cell_of[i] = g.index(g.coord(p.x, 0), g.coord(p.y, 1), g.coord(p.z, 2));
        ++g.start[cell_of[i] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) g.start[c + 1] += g.start[c];
    g.order.resize(points.size());
    std::vector<std::uint32_t> fill(g.start.begin(), g.start.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) g.order[fill[cell_of[i]]++] = std::uint32_t(i);
    return g;
}

// Keeps the k nearest points seen (squared distance and index), ascending.
struct Best {
    static constexpr int kCapacity = 16;
    std::array<double, kCapacity> d{};
    std::array<std::uint32_t, kCapacity> index{};
    int k = 0, n = 0;
    void push(double v, std::uint32_t j) {
        if (n == k && v >= d[std::size_t(k - 1)]) return;
        int i = n < k ? n++ : k - 1;
        while (i > 0 && d[std::size_t(i - 1)] > v) {
            d[std::size_t(i)] = d[std::size_t(i - 1)], index[std::size_t(i)] = index[std::size_t(i - 1)];
            --i;
        }
        d[std::size_t(i)] = v, index[std::size_t(i)] = j;
    }
    double worst() const { return n < k ? std::numeric_limits<double>::infinity() : d[std::size_t(k - 1)]; }
};

void visit_cell(const Grid& g, const std::vector<Vec3f>& pts, std::size_t self, int x, int y, int z,
                Best& best) {
    const std::size_t c = g.index(x, y, z);
    const Vec3f& p = pts[self];
    for (std::uint32_t e = g.start[c]; e < g.start[c + 1]; ++e) {
        const std::uint32_t j = g.order[e];
        if (j == self) continue;
        const double dx = double(pts[j].x) - p.x, dy = double(pts[j].y) - p.y, dz = double(pts[j].z) - p.z;
        best.push(dx * dx + dy * dy + dz * dz, j);
    }
}

// The cells at Chebyshev distance exactly r from `c`, clipped to the grid, each visited once: rows on the
// shell's faces in full, other rows only at their two ends. Costs the clipped shell, not the cube.
void visit_shell(const Grid& g, const std::vector<Vec3f>& pts, std::size_t self, std::array<int, 3> c, int r,
                 Best& best) {
    const int x0 = std::max(c[0] - r, 0), x1 = std::min(c[0] + r, g.dims[0] - 1);
    const int y0 = std::max(c[1] - r, 0), y1 = std::min(c[1] + r, g.dims[1] - 1);
    const int z0 = std::max(c[2] - r, 0), z1 = std::min(c[2] + r, g.dims[2] - 1);
    for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y) {
            if (std::abs(z - c[2]) == r || std::abs(y - c[1]) == r) {
                for (int x = x0; x <= x1; ++x) visit_cell(g, pts, self, x, y, z, best);
                continue;
            }
            if (c[0] - r >= 0) visit_cell(g, pts, self, c[0] - r, y, z, best);
            if (r > 0 && c[0] + r < g.dims[0]) visit_cell(g, pts, self, c[0] + r, y, z, best);
        }
}

// The k nearest other points of every point, by growing shells of cells around its own.
template <typename F>
void for_each_knn(const std::vector<Vec3f>& points, int k, F&& f) {
    const Grid g = build_grid(points);
    const int max_ring = std::max({g.dims[0], g.dims[1], g.dims[2]});
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Vec3f& p = points[i];
        const int cx = g.coord(p.x, 0), cy = g.coord(p.y, 1), cz = g.coord(p.z, 2);
        Best best;
        best.k = k;
        for (int r = 0; r <= max_ring; ++r) {
            visit_shell(g, points, i, {cx, cy, cz}, r, best);
            // Unvisited points lie outside cells c-r..c+r on some axis, so at least r * cell away from p (p
            // lies inside its cell, or beyond the border on a clamped axis, which only adds distance).
            const double bound = double(r) * g.cell;
            if (best.n == best.k && best.worst() <= bound * bound) break;
        }
        f(i, best);
    }
}

}  // namespace

std::vector<double> mean_sq_dist_knn(const std::vector<Vec3f>& points, int k) {
    k = std::clamp(k, 1, 8);
    std::vector<double> out(points.size(), 0.0);
    if (points.size() < 2) return out;
    for_each_knn(points, k, [&](std::size_t i, const Best& best) {
        double sum = 0;
        for (int j = 0; j < best.n; ++j) sum += best.d[std::size_t(j)];
        out[i] = best.n > 0 ? sum / best.n : 0.0;
    });
    return out;
}

std::vector<std::uint32_t> knn_indices(const std::vector<Vec3f>& points, int k) {
    k = std::clamp(k, 1, Best::kCapacity);
    std::vector<std::uint32_t> out(points.size() * std::size_t(k));
    if (points.empty()) return out;
    for_each_knn(points, k, [&](std::size_t i, const Best& best) {
        for (int j = 0; j < k; ++j)  // fewer than k others: repeat the point itself
            out[i * std::size_t(k) + std::size_t(j)] =
                j < best.n ? best.index[std::size_t(j)] : std::uint32_t(i);
    });
    return out;
}

}  // namespace lumigauss
