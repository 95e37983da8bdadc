#pragma once
// Starting points on the ground where the SfM points leave it bare. Photos of a place are taken standing on
// its ground, and SfM finds few points on the ground near the cameras: it is seen there steeply by one photo
// and at a grazing angle by the others. Nothing then starts there, the far photos never grow surfels into
// it, and a view from among the cameras looks down through holes (issue #25: the worst plaza and demo test
// views leave 20-50 % of their pixels empty, all of it near ground). This finds the ground plane under the
// cameras from the SfM points and adds points on it, in the cells of a grid around the cameras' feet where no
// SfM point lies, coloured as the nearest ground point. Training then keeps what the photos support: a seed
// that no photo sees is pruned after the first opacity reset.
#include <cstddef>
#include <vector>

#include "lumigauss/math/vec.h"

namespace lumigauss {

struct GroundSeedOptions {
    // How far around each camera's foot the ground is filled, as a fraction of the camera extent (the
    // radius of the cameras about their centre, io/scene_extent.h).
    double reach = 0.25;
    // At most this many seeds (the grid is coarsened to fit); 0 = as many as the SfM points.
    std::size_t max_seeds = 0;
};

struct GroundSeeds {
    bool found = false;             // a ground plane below the cameras held enough SfM points
    double height = 0;              // the plane's height along `up`
    std::size_t ground_points = 0;  // SfM points on it
    double spacing = 0;             // grid cell side of the seeds
    std::vector<Vec3f> xyz, rgb;    // the seeds (none when not found)
};

// The ground is the most populated height (bins of 0.005 x extent) among the SfM points below the cameras'
// median height along `up` (unit, the cameras' mean up), taken when it holds at least a quarter of them and
// 30 points. The grid spacing is twice the median nearest-neighbour distance of the ground points.
GroundSeeds ground_seeds(const std::vector<Vec3f>& points, const std::vector<Vec3f>& colours,
                         const std::vector<Vec3d>& camera_centres, Vec3d up, double extent,
                         const GroundSeedOptions& options = {});

}  // namespace lumigauss
