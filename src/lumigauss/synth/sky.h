#pragma once
// Lighting conditions of the synthetic photos: a smooth sky whose radiance is exactly a degree-2 SH (so its
// unshadowed irradiance is exactly the Ramamoorthi-Hanrahan formula) plus a sun disc of 1 degree diameter
// (direction, colour, power) that casts hard shadows. The environment written for evaluation
// (env/COND_sh.txt) is the sky SH plus the sun disc's SH projection, like data/plaza ("sun included").
#include <cstdint>
#include <string>
#include <vector>

#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss::synth {

// Size of the published environment maps and of the grid the sun direction is snapped to (as in plaza).
inline constexpr int kEnvWidth = 128;
inline constexpr int kEnvHeight = 64;
inline constexpr double kSunDiameterDeg = 1.0;
// Every condition is scaled so that the largest irradiance over upward and sideways normals is this (plaza's
// calibration), which keeps well-exposed photos at exposures around 1.
inline constexpr double kMaxIrradiance = 3.8;

struct LightCondition {
    std::string id;     // "sky00", "sky01", ...
    std::string split;  // "train" or "test": a test condition lights no training photo
    bool overcast = false;
    ShCoeffs<double> sky_sh;  // sky radiance without the sun (non-negative everywhere)
    Vec3d sun_dir;            // unit, world frame, pointing towards the sun
    Vec3d sun_power;          // irradiance the sun gives a surface facing it: integral of the disc radiance
    double strength = 1.0;    // the calibration factor folded into sky_sh and sun_power
    int sun_row = 0, sun_col = 0;  // the 128 x 64 env-map pixel whose centre is sun_dir
};

// Conditions sky00.. : n_train for training photos, then n_test unseen ones for test photos.
std::vector<LightCondition> make_conditions(int n_train, int n_test, std::uint64_t seed);

// Sky SH plus the sun disc's SH projection: the ground-truth environment of the condition.
ShCoeffs<double> environment_sh(const LightCondition& c);

// What a camera ray that misses the scene sees: the sky SH (clamped at 0) plus the sun disc.
Vec3d sky_radiance(const LightCondition& c, Vec3d dir);

// Irradiance of an unoccluded surface with normal n: sky part (R-H, exact for the SH sky) and sun part.
Vec3d sky_irradiance(const LightCondition& c, Vec3d n);
Vec3d sun_irradiance(const LightCondition& c, Vec3d n);

// The environment as an equirectangular map (kEnvWidth x kEnvHeight, plaza's mapping, radiance): the sky SH
// in every pixel and the sun's power in the pixel it was snapped to (value = power / pixel solid angle).
Image environment_panorama(const LightCondition& c);

double sun_elevation_deg(const LightCondition& c);
double sun_azimuth_deg(const LightCondition& c);  // atan2(y, x) of the sun direction

}  // namespace lumigauss::synth
