#pragma once
// How much light the surfels of a model let through along a ray: the product of (1 - alpha) over every surfel
// disk the ray crosses, alpha = min(0.99, opacity * exp(-r^2 / 2)) at the crossing point as the rasterizer
// composites it (research/2dgs_rasterizer.md). The surfels are binned into a uniform grid (each into every
// cell its 3-sigma disk's box touches) and a ray walks the cells it passes (Amanatides-Woo), testing each
// surfel once. What casts a shadow on what (issue #25): the ray tracer of a shadow, not a renderer.
#include <cstdint>
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

class SurfelOcclusion {
  public:
    // Surfels fainter than min_opacity cast no shadow. The grid spans the box of the central 98 % of the
    // surfel centres on each axis and the disks centred in it, widened by at most half the box's largest
    // side: far floaters cast no shadow on the scene.
    explicit SurfelOcclusion(const SurfelModel& model, double min_opacity = 1.0 / 255.0);

    // Scratch for one thread: which surfels the current ray has already tested.
    struct RayScratch {
        std::vector<std::uint32_t> tested_by_ray;
        std::uint32_t ray = 0;
    };
    RayScratch scratch() const;

    // A shadow ray from a surfel (or any point: self = the model's size).
    struct Ray {
        Vec3d origin, dir;     // dir: unit
        double t_min = 0.0;    // crossings nearer than this do not count
        std::size_t self = 0;  // the surfel the ray leaves from, which does not shade itself
        // The surface the ray leaves: surfels lying nearly parallel to it (within kLayerCos) and less than
        // layer_thickness off its plane are layers of the same surface, not what shades it (0: none).
        Vec3d surface_normal{0, 0, 1};
        double layer_thickness = 0.0;
    };
    // Transmittance along origin + t * dir, t > t_min; stops early once below `stop_below` (returns 0).
    double transmittance(const Ray& ray, RayScratch& scratch, double stop_below = 1e-3) const;
    static constexpr double kLayerCos = 0.9;

    double cell_size() const { return cell_; }
    Vec3d grid_min() const { return lo_; }
    Vec3d grid_max() const { return hi_; }

  private:
    struct Disk {
        Vec3d centre, axis_u, axis_v, normal;  // axes divided by their scale: local coordinate = (x-c).axis
        double opacity;
    };
    static Vec3d box_reach(const Disk& d);
    double crossing_alpha(const Disk& d, const Ray& ray) const;

    std::vector<Disk> disks_;
    std::vector<std::uint32_t> disk_index_;  // the surfel index in the model of each disk
    Vec3d lo_, hi_;
    double cell_ = 1.0;
    int dims_[3] = {1, 1, 1};
    std::vector<std::uint32_t>
        cell_start_;  // CSR: cell c holds cell_items_[cell_start_[c] .. cell_start_[c+1])
    std::vector<std::uint32_t> cell_items_;
};

}  // namespace lumigauss
