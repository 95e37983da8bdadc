#include "lumigauss/cameras/ground_plane.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumigauss/math/symmetric_eigen.h"
#include "lumigauss/util/rng.h"

namespace lumigauss {

namespace {

enum class GroundRandom { kSample };

constexpr std::size_t kMaxPoints = 20000;  // a larger cloud is thinned by a stride (the plane needs few)
constexpr int kTrials = 300;

// The finite points, thinned by a stride to at most kMaxPoints.
std::vector<Vec3d> finite_points(const std::vector<Vec3d>& points) {
    std::vector<Vec3d> finite;
    for (const Vec3d& p : points)
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) finite.push_back(p);
    if (finite.size() <= kMaxPoints) return finite;
    const std::size_t stride = (finite.size() + kMaxPoints - 1) / kMaxPoints;
    std::vector<Vec3d> thinned;
    for (std::size_t i = 0; i < finite.size(); i += stride) thinned.push_back(finite[i]);
    return thinned;
}

// The points below the median camera height along `up`: where the ground is looked for.
std::vector<Vec3d> points_below(const std::vector<Vec3d>& points, const std::vector<Vec3d>& centres,
                                Vec3d up) {
    std::vector<double> heights;
    for (const Vec3d& c : centres) heights.push_back(dot(c, up));
    std::nth_element(heights.begin(), heights.begin() + std::ptrdiff_t(heights.size() / 2), heights.end());
    const double camera_height = heights[heights.size() / 2];
    std::vector<Vec3d> below;
    for (const Vec3d& p : points)
        if (dot(p, up) < camera_height) below.push_back(p);
    return below;
}

// The distance within which a point lies on the plane: 1 % of the cameras' spread about their mean, or of
// the points' when the cameras are at one place.
double inlier_distance(const std::vector<Vec3d>& centres, const std::vector<Vec3d>& points) {
    const auto spread = [](const std::vector<Vec3d>& v) {
        Vec3d mean{};
        for (const Vec3d& p : v) mean += p;
        mean = (1.0 / double(v.size())) * mean;
        double r = 0;
        for (const Vec3d& p : v) r = std::max(r, length(p - mean));
        return r;
    };
    const double cameras = spread(centres);
    return 0.01 * (cameras > 0 ? cameras : spread(points));
}

std::size_t count_inliers(const std::vector<Vec3d>& points, Vec3d n, double offset, double tolerance) {
    std::size_t count = 0;
    for (const Vec3d& p : points) count += std::abs(dot(n, p) - offset) <= tolerance ? 1 : 0;
    return count;
}

// The least-squares plane of the points within `tolerance` of (n, offset): its normal is the smallest
// eigenvector of their scatter about their mean.
GroundPlane refit(const std::vector<Vec3d>& points, Vec3d n, double offset, double tolerance, Vec3d up) {
    Vec3d mean{};
    std::size_t count = 0;
    for (const Vec3d& p : points)
        if (std::abs(dot(n, p) - offset) <= tolerance) mean += p, ++count;
    GroundPlane g;
    if (count < 3) return g;
    mean = (1.0 / double(count)) * mean;
    Mat3d scatter{};
    for (const Vec3d& p : points) {
        if (std::abs(dot(n, p) - offset) > tolerance) continue;
        const Vec3d d = p - mean;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) scatter(i, j) += d[i] * d[j];
    }
    Vec3d normal = symmetric_eigen(scatter).vectors[0];
    if (dot(normal, up) < 0) normal = -1.0 * normal;
    g.normal = normal;
    g.offset = dot(normal, mean);
    g.inliers = count_inliers(points, g.normal, g.offset, tolerance);
    return g;
}

}  // namespace

GroundPlane find_ground_plane(const std::vector<Vec3d>& points, const std::vector<Vec3d>& camera_centres,
                              Vec3d up_guess) {
    GroundPlane none;
    if (camera_centres.empty() || !(length(up_guess) > 0)) return none;
    const Vec3d up = normalize(up_guess);
    const std::vector<Vec3d> finite = finite_points(points);
    const std::vector<Vec3d> below = points_below(finite, camera_centres, up);
    none.candidates = below.size();
    if (below.size() < 20) return none;
    const double tolerance = inlier_distance(camera_centres, below);
    if (!(tolerance > 0)) return none;
    const double min_cos = std::cos(kMaxGroundTilt * std::numbers::pi / 180.0);
    Rng rng(0, GroundRandom::kSample);
    const int last = int(below.size()) - 1;
    Vec3d best_normal{};
    double best_offset = 0;
    std::size_t best = 0;
    for (int trial = 0; trial < kTrials; ++trial) {
        const Vec3d& a = below[std::size_t(rng.uniform_int(0, last))];
        const Vec3d& b = below[std::size_t(rng.uniform_int(0, last))];
        const Vec3d& c = below[std::size_t(rng.uniform_int(0, last))];
        Vec3d n = cross(b - a, c - a);
        if (!(length(n) > 0)) continue;
        n = normalize(n);
        if (dot(n, up) < 0) n = -1.0 * n;
        if (dot(n, up) < min_cos) continue;
        const std::size_t inliers = count_inliers(below, n, dot(n, a), tolerance);
        if (inliers > best) best = inliers, best_normal = n, best_offset = dot(n, a);
    }
    if (best < 20 || 5 * best < below.size()) return none;
    // Refitted to every point on the plane: with a tilted guess, part of the ground lies above the cameras'
    // height along it.
    GroundPlane g = refit(finite, best_normal, best_offset, tolerance, up);
    g.candidates = below.size();
    g.found = g.inliers >= 20 && dot(g.normal, up) >= min_cos;
    return g.found ? g : none;
}

}  // namespace lumigauss
