#pragma once
// A structure-from-motion-like point cloud for the synthetic scenes (COLMAP points3D with tracks), made
// the way data/plaza's was: points sampled on the surfaces, kept when at least two training photos see
// them (in frame, viewed at less than 87 degrees from the normal, unoccluded -- pedestrians included),
// with Gaussian position noise, the exact projections of the noise-free point as 2D observations, and the
// mean 8-bit colour of the training pixels at those observations.
#include <array>
#include <cstdint>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/synth/world.h"

namespace lumigauss::synth {

// One training photo as the sampler needs it.
struct TrainingView {
    const World* world = nullptr;  // the landmark plus that photo's pedestrians
    const Camera* camera = nullptr;
    const std::vector<std::uint8_t>* rgb8 = nullptr;  // the written photo, interleaved RGB
};

struct Observation {
    int view = 0;         // index into the training views
    double x = 0, y = 0;  // pixel coordinates (origin at the top-left corner)
};

struct SfmPoint {
    Vec3d position;  // with noise, as written
    Vec3d surface;   // the noise-free point on the surface
    Vec3d normal;
    std::array<std::uint8_t, 3> rgb{};
    double error = 0;  // RMS reprojection error of `position` against the observations, pixels
    std::vector<Observation> track;
};

struct SfmSamplingOptions {
    int candidates = 8000;       // surface samples tried; half on the landmark, half on the ground
    double noise_sigma = 0.0;    // per-axis standard deviation of the position noise, metres
    double ground_radius = 100;  // ground samples within this distance of the landmark's centre
    std::uint64_t seed = 1;
};

std::vector<SfmPoint> sample_sfm_points(const Landmark& landmark, const std::vector<TrainingView>& views,
                                        const SfmSamplingOptions& options);

// Projection of a world point into a camera (x, y in pixels; z the depth).
Vec3d project(const Camera& camera, Vec3d p);

}  // namespace lumigauss::synth
