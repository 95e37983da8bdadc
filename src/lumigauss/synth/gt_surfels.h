#pragma once
// Ground-truth surfels (gt/surfels.ply): the static scene's geometry and albedo as a 2D Gaussian surfel model
// in the 2DGS PLY layout, so that a surfel renderer can be checked against gt/albedo and a trained model
// against the true geometry.
//
// One surfel per cell of a grid laid over each face of the landmark's primitives (primitives.h's face maps,
// uniform by area, so the cells of a face have equal areas) and over the ground, kept when some photo sees
// the cell's centre or a point near one of its corners (facing the camera, in frame, unoccluded by the
// static scene). About half the surfels are on the landmark, half on the ground. The ground has one cell
// size out to a radius enclosing every camera and, beyond it, cells that grow with the cube of the
// distance out to the ground's edge (far ground is seen at a grazing angle through few pixels). A surfel
// sits at its cell's centre, in the surface (normal = third rotation column = the true outward normal);
// its scales are its cell's side lengths times kScalePerCell (neighbours overlap, the surface renders
// closed); its opacity is kOpacity; its colour (SH degree 0) is the true linear albedo averaged over its
// cell: f_dc = (albedo - 0.5) / C0, C0 = 0.28209479177387814, so that 0.5 + C0 f_dc = albedo.
//
// Deterministic: no randomness at all (the cell sizes are fitted to the target count by a pilot run).
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/model/splat_ply.h"
#include "lumigauss/synth/world.h"

namespace lumigauss::synth {

inline constexpr double kScalePerCell = 0.6;  // surfel sigma / cell side
inline constexpr double kOpacity = 0.98;      // every surfel's opacity
inline constexpr int kAlbedoSamples = 3;  // colour: the mean albedo at kAlbedoSamples^2 points of the cell

struct GtSurfelOptions {
    int target_count = 60000;  // about this many surfels are kept (the cell size is fitted to it)
};

struct GtSurfels {
    ViewDependentSurfels model;  // SH degree 0
    double cell = 0;             // landmark cell side, metres
    double ground_cell = 0;      // ground cell side within near_radius, metres
    double near_radius = 0;      // the ground's cells grow beyond this distance from the landmark's centre
};

// The static landmark (pedestrians excluded) as seen by `cameras`.
GtSurfels make_gt_surfels(const Landmark& landmark, const std::vector<Camera>& cameras,
                          const GtSurfelOptions& options);

}  // namespace lumigauss::synth
