#include "lumigauss/train/ground_seeds.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "lumigauss/model/knn.h"

namespace lumigauss {
namespace {

constexpr std::size_t kMinGroundPoints = 30;
constexpr std::size_t kMaxCells = std::size_t(1) << 22;  // grid cells examined; coarser beyond

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

// Two unit vectors spanning the plane perpendicular to the unit `up`.
void plane_basis(Vec3d up, Vec3d& e1, Vec3d& e2) {
    const Vec3d helper = std::abs(up.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    e1 = normalize(cross(helper, up));
    e2 = cross(up, e1);
}

std::int64_t cell_key(std::int64_t i, std::int64_t j) {
    return (i << 32) ^ (j & 0xffffffff);
}

// The ground height: the fullest height bin among the points below the cameras, refined to the median of
// the points within a bin of it. Returns false when it holds too few of them.
bool find_ground(const std::vector<double>& heights, double camera_height, double bin, double& ground,
                 std::size_t& count) {
    std::unordered_map<std::int64_t, std::size_t> bins;
    std::size_t below = 0;
    for (double h : heights)
        if (h < camera_height) ++bins[std::int64_t(std::floor(h / bin))], ++below;
    if (bins.empty()) return false;
    const auto best = std::max_element(bins.begin(), bins.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    const double centre = (double(best->first) + 0.5) * bin;
    std::vector<double> near;
    for (double h : heights)
        if (std::abs(h - centre) <= bin) near.push_back(h);
    ground = median(near);
    count = 0;
    for (double h : heights) count += std::abs(h - ground) <= bin ? 1 : 0;
    return count >= kMinGroundPoints && 4 * count >= below;
}

}  // namespace

GroundSeeds ground_seeds(const std::vector<Vec3f>& points, const std::vector<Vec3f>& colours,
                         const std::vector<Vec3d>& camera_centres, Vec3d up, double extent,
                         const GroundSeedOptions& options) {
    GroundSeeds out;
    if (points.size() < kMinGroundPoints || camera_centres.empty() || !(length(up) > 0) || !(extent > 0))
        return out;
    up = normalize(up);
    std::vector<double> heights(points.size()), camera_heights;
    for (std::size_t i = 0; i < points.size(); ++i) heights[i] = dot(points[i].cast<double>(), up);
    for (const Vec3d& c : camera_centres) camera_heights.push_back(dot(c, up));
    const double bin = 0.005 * extent;
    if (!find_ground(heights, median(camera_heights), bin, out.height, out.ground_points)) return out;
    out.found = true;

    // The ground points, in plane coordinates; their spacing sets the grid's.
    Vec3d e1, e2;
    plane_basis(up, e1, e2);
    std::vector<Vec3f> ground;
    std::vector<std::size_t> ground_index;
    for (std::size_t i = 0; i < points.size(); ++i)
        if (std::abs(heights[i] - out.height) <= bin) ground.push_back(points[i]), ground_index.push_back(i);
    std::vector<double> spacing;
    for (double d2 : mean_sq_dist_knn(ground, 1)) spacing.push_back(std::sqrt(d2));
    double s = std::max(2 * median(spacing), 0.002 * extent);

    // The cameras' feet, and the box around them that the reach covers.
    const double reach = options.reach * extent;
    std::vector<std::pair<double, double>> feet;
    double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
    for (const Vec3d& c : camera_centres) {
        const double u = dot(c, e1), v = dot(c, e2);
        feet.push_back({u, v});
        u0 = std::min(u0, u - reach), u1 = std::max(u1, u + reach);
        v0 = std::min(v0, v - reach), v1 = std::max(v1, v + reach);
    }
    const double area_cells = (u1 - u0) * (v1 - v0) / (s * s);
    if (area_cells > double(kMaxCells)) s *= std::sqrt(area_cells / double(kMaxCells));
    const std::size_t limit = options.max_seeds > 0 ? options.max_seeds : points.size();

    for (;;) {  // coarsened until the seeds fit the limit
        // Cells holding any SfM point near the plane are not bare; ground points by cell for the colours.
        std::unordered_set<std::int64_t> occupied;
        std::unordered_map<std::int64_t, std::vector<std::size_t>> by_cell;
        const auto cell_of = [&](double u, double v) {
            return std::pair{std::int64_t(std::floor((u - u0) / s)), std::int64_t(std::floor((v - v0) / s))};
        };
        for (std::size_t i = 0; i < points.size(); ++i) {
            if (std::abs(heights[i] - out.height) > 3 * bin) continue;
            const Vec3d p = points[i].cast<double>();
            const auto [ci, cj] = cell_of(dot(p, e1), dot(p, e2));
            occupied.insert(cell_key(ci, cj));
        }
        for (std::size_t g = 0; g < ground.size(); ++g) {
            const Vec3d p = ground[g].cast<double>();
            const auto [ci, cj] = cell_of(dot(p, e1), dot(p, e2));
            by_cell[cell_key(ci, cj)].push_back(ground_index[g]);
        }
        const auto nearest_colour = [&](std::int64_t ci, std::int64_t cj, double u, double v) {
            for (std::int64_t ring = 0; ring <= 64; ++ring) {
                double best = 1e300;
                std::size_t found = points.size();
                for (std::int64_t di = -ring; di <= ring; ++di)
                    for (std::int64_t dj = -ring; dj <= ring; ++dj) {
                        if (std::max(std::abs(di), std::abs(dj)) != ring) continue;
                        const auto it = by_cell.find(cell_key(ci + di, cj + dj));
                        if (it == by_cell.end()) continue;
                        for (std::size_t i : it->second) {
                            const Vec3d p = points[i].cast<double>();
                            const double du = dot(p, e1) - u, dv = dot(p, e2) - v;
                            if (du * du + dv * dv < best) best = du * du + dv * dv, found = i;
                        }
                    }
                if (found < points.size()) return colours[found];
            }
            return colours[ground_index.front()];
        };
        out.xyz.clear(), out.rgb.clear();
        const std::int64_t ni = std::int64_t(std::ceil((u1 - u0) / s)),
                           nj = std::int64_t(std::ceil((v1 - v0) / s));
        for (std::int64_t i = 0; i < ni && out.xyz.size() <= limit; ++i)
            for (std::int64_t j = 0; j < nj; ++j) {
                if (occupied.count(cell_key(i, j))) continue;
                const double u = u0 + (double(i) + 0.5) * s, v = v0 + (double(j) + 0.5) * s;
                bool near_a_foot = false;
                for (const auto& [fu, fv] : feet)
                    if ((fu - u) * (fu - u) + (fv - v) * (fv - v) <= reach * reach) {
                        near_a_foot = true;
                        break;
                    }
                if (!near_a_foot) continue;
                out.xyz.push_back((u * e1 + v * e2 + out.height * up).cast<float>());
                out.rgb.push_back(nearest_colour(i, j, u, v));
            }
        if (out.xyz.size() <= limit) break;
        s *= 1.25;
    }
    out.spacing = s;
    return out;
}

}  // namespace lumigauss
