#include "lumigauss/model/surfel_occlusion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "lumigauss/math/quaternion.h"

namespace lumigauss {

namespace {

constexpr double kDiskSigmas = 3.0;  // a disk ends where its Gaussian falls below exp(-4.5) = 1.1 %
constexpr double kAlphaCap = 0.99;   // the rasterizer's cap, so that one surfel never blocks all light
constexpr double kAlphaFloor = 1.0 / 255.0;
constexpr double kCellsPerDisk = 8.0;  // grid resolution: about this many cells per shadow-casting surfel
constexpr double kMinCells = 4096.0, kMaxCells = 8.0e6;
constexpr int kMaxCellsPerAxis = 1024;
constexpr double kCentralFraction = 0.98, kWiden = 0.5;

// The q-quantile of v, rounded outwards (down below the median, up above it), so that a handful of surfels
// keep all of theirs.
double percentile(std::vector<double> v, double q) {
    const double at = q * double(v.size() - 1);
    const auto k = static_cast<std::size_t>(q < 0.5 ? std::floor(at) : std::ceil(at));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
}

}  // namespace

// Half the sides of the box around a disk's 3-sigma ellipse: per world axis, 3 sqrt((s_u u_a)^2 + (s_v
// v_a)^2).
Vec3d SurfelOcclusion::box_reach(const Disk& d) {
    const double su = 1.0 / length(d.axis_u), sv = 1.0 / length(d.axis_v);
    Vec3d reach;
    for (int a = 0; a < 3; ++a) {
        const double eu = d.axis_u[a] * su * su, ev = d.axis_v[a] * sv * sv;  // world axis times its scale
        reach[a] = kDiskSigmas * std::sqrt(eu * eu + ev * ev);
    }
    return reach;
}

SurfelOcclusion::SurfelOcclusion(const SurfelModel& model, double min_opacity) {
    const auto& xyz = model.param(ModelParam::Xyz);
    const auto& scaling = model.param(ModelParam::Scaling);
    const auto& opacity = model.param(ModelParam::Opacity);
    for (std::size_t i = 0; i < model.size(); ++i) {
        const float o = sigmoid(opacity[i]);
        const double su = std::exp(double(scaling[2 * i])), sv = std::exp(double(scaling[2 * i + 1]));
        const Vec3d c{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
        if (!(o >= min_opacity) || !(su > 0 && sv > 0 && std::isfinite(su) && std::isfinite(sv))) continue;
        if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) continue;
        const Mat3<float> r = rotation_from_unit_quaternion(model.unit_quaternion(i));
        disks_.push_back({c, r.col(0).cast<double>() * (1.0 / su), r.col(1).cast<double>() * (1.0 / sv),
                          r.col(2).cast<double>(), double(o)});
        disk_index_.push_back(std::uint32_t(i));
    }
    if (disks_.empty()) {
        lo_ = hi_ = {0, 0, 0};
        cell_start_.assign(2, 0);
        return;
    }
    // The box of the central centres, grown to hold the disks centred in it, but by no more than half its
    // largest side: a floater, or one surfel metres wide at the edge, does not stretch the grid.
    const double tail = (1.0 - kCentralFraction) / 2.0;
    Vec3d central_lo, central_hi;
    for (int a = 0; a < 3; ++a) {
        std::vector<double> coordinate(disks_.size());
        for (std::size_t k = 0; k < disks_.size(); ++k) coordinate[k] = disks_[k].centre[a];
        central_lo[a] = percentile(coordinate, tail);
        central_hi[a] = percentile(coordinate, 1.0 - tail);
    }
    const Vec3d central = central_hi - central_lo;
    const double grow_limit = kWiden * std::max({central.x, central.y, central.z}) + 1e-3;
    lo_ = central_lo;
    hi_ = central_hi;
    for (const Disk& d : disks_) {
        bool inside = true;
        for (int a = 0; a < 3; ++a)
            inside = inside && d.centre[a] >= central_lo[a] && d.centre[a] <= central_hi[a];
        if (!inside) continue;
        const Vec3d reach = box_reach(d);
        for (int a = 0; a < 3; ++a) {
            lo_[a] = std::min(lo_[a], d.centre[a] - reach[a]);
            hi_[a] = std::max(hi_[a], d.centre[a] + reach[a]);
        }
    }
    for (int a = 0; a < 3; ++a) {
        lo_[a] = std::max(lo_[a], central_lo[a] - grow_limit) - 1e-3;
        hi_[a] = std::min(hi_[a], central_hi[a] + grow_limit) + 1e-3;
    }
    const Vec3d size = hi_ - lo_;
    const double cells = std::clamp(kCellsPerDisk * double(disks_.size()), kMinCells, kMaxCells);
    cell_ = std::cbrt(size.x * size.y * size.z / cells);
    for (int a = 0; a < 3; ++a) {
        cell_ = std::max(cell_, size[a] / kMaxCellsPerAxis);
    }
    for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, int(std::ceil(size[a] / cell_)));

    // Two passes over every disk's cells (count, then fill): a cell holds the disks whose plane passes
    // through it within the disk's 3-sigma box.
    const std::size_t cell_count = std::size_t(dims_[0]) * std::size_t(dims_[1]) * std::size_t(dims_[2]);
    cell_start_.assign(cell_count + 1, 0);
    auto for_each_cell = [&](const Disk& d, auto&& visit) {
        int first[3], last[3];
        const Vec3d reach = box_reach(d);
        for (int a = 0; a < 3; ++a) {
            first[a] = std::max(0, int(std::floor((d.centre[a] - reach[a] - lo_[a]) / cell_)));
            last[a] = std::min(dims_[a] - 1, int(std::floor((d.centre[a] + reach[a] - lo_[a]) / cell_)));
            if (first[a] > last[a]) return;
        }
        const double slab =
            0.5 * cell_ * (std::abs(d.normal.x) + std::abs(d.normal.y) + std::abs(d.normal.z));
        for (int z = first[2]; z <= last[2]; ++z)
            for (int y = first[1]; y <= last[1]; ++y)
                for (int x = first[0]; x <= last[0]; ++x) {
                    const Vec3d mid{lo_.x + (x + 0.5) * cell_, lo_.y + (y + 0.5) * cell_,
                                    lo_.z + (z + 0.5) * cell_};
                    const Vec3d off = mid - d.centre;
                    if (std::abs(dot(off, d.normal)) > slab) continue;  // the plane misses this cell
                    visit((std::size_t(z) * dims_[1] + y) * dims_[0] + x);
                }
    };
    for (const Disk& d : disks_) for_each_cell(d, [&](std::size_t c) { ++cell_start_[c + 1]; });
    for (std::size_t c = 0; c < cell_count; ++c) cell_start_[c + 1] += cell_start_[c];
    cell_items_.resize(cell_start_[cell_count]);
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t k = 0; k < disks_.size(); ++k)
        for_each_cell(disks_[k], [&](std::size_t c) { cell_items_[fill[c]++] = std::uint32_t(k); });
}

SurfelOcclusion::RayScratch SurfelOcclusion::scratch() const {
    return {std::vector<std::uint32_t>(disks_.size(), 0), 0};
}

double SurfelOcclusion::crossing_alpha(const Disk& d, const Ray& ray) const {
    if (ray.layer_thickness > 0.0 && std::abs(dot(d.normal, ray.surface_normal)) > kLayerCos &&
        std::abs(dot(d.centre - ray.origin, ray.surface_normal)) < ray.layer_thickness)
        return 0.0;  // another layer of the same surface
    const Vec3d origin = ray.origin, dir = ray.dir;
    const double t_min = ray.t_min;
    const Vec3d n = d.normal;
    const double facing = dot(dir, n);
    if (std::abs(facing) < 1e-9) return 0.0;
    const double t = dot(d.centre - origin, n) / facing;
    if (!(t > t_min)) return 0.0;
    const Vec3d x = origin + dir * t - d.centre;
    const double u = dot(x, d.axis_u), v = dot(x, d.axis_v);
    const double r2 = u * u + v * v;
    if (r2 > kDiskSigmas * kDiskSigmas) return 0.0;
    const double alpha = std::min(kAlphaCap, double(d.opacity) * std::exp(-0.5 * r2));
    return alpha < kAlphaFloor ? 0.0 : alpha;
}

double SurfelOcclusion::transmittance(const Ray& ray, RayScratch& scratch, double stop_below) const {
    const Vec3d origin = ray.origin, dir = ray.dir;
    if (cell_items_.empty()) return 1.0;
    // The ray's stretch inside the grid (slab test).
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (std::abs(dir[a]) < 1e-12) {
            if (origin[a] < lo_[a] || origin[a] > hi_[a]) return 1.0;
            continue;
        }
        double ta = (lo_[a] - origin[a]) / dir[a], tb = (hi_[a] - origin[a]) / dir[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (!(t0 < t1)) return 1.0;
    if (++scratch.ray == 0) {  // the stamp wrapped: forget every old stamp
        std::fill(scratch.tested_by_ray.begin(), scratch.tested_by_ray.end(), 0);
        scratch.ray = 1;
    }
    const Vec3d start = origin + dir * t0;
    int cell[3], step[3];
    double next[3], delta[3];
    for (int a = 0; a < 3; ++a) {
        cell[a] = std::clamp(int(std::floor((start[a] - lo_[a]) / cell_)), 0, dims_[a] - 1);
        if (dir[a] > 0) {
            step[a] = 1;
            next[a] = t0 + (lo_[a] + (cell[a] + 1) * cell_ - start[a]) / dir[a];
            delta[a] = cell_ / dir[a];
        } else if (dir[a] < 0) {
            step[a] = -1;
            next[a] = t0 + (lo_[a] + cell[a] * cell_ - start[a]) / dir[a];
            delta[a] = -cell_ / dir[a];
        } else {
            step[a] = 0;
            next[a] = delta[a] = std::numeric_limits<double>::infinity();
        }
    }
    double light = 1.0;
    while (true) {
        const std::size_t c = (std::size_t(cell[2]) * dims_[1] + cell[1]) * dims_[0] + cell[0];
        for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
            const std::uint32_t item = cell_items_[k];
            if (scratch.tested_by_ray[item] == scratch.ray) continue;
            scratch.tested_by_ray[item] = scratch.ray;
            if (disk_index_[item] == ray.self) continue;
            light *= 1.0 - crossing_alpha(disks_[item], ray);
            if (light < stop_below) return 0.0;
        }
        const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        if (next[a] > t1) break;
        cell[a] += step[a];
        if (cell[a] < 0 || cell[a] >= dims_[a]) break;
        next[a] += delta[a];
    }
    return light;
}

}  // namespace lumigauss
