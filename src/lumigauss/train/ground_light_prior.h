#pragma once
// The light below the horizon is the ground's reflection. No surface of an outdoor scene faces down, so
// the photos do not constrain the lower half of a learned light; yet a wall sees half of it, and through it
// the lights trade the walls' brightness against their albedo: the learned lights of plaza carry 20-40x the
// true light from below, and the walls' albedo comes out a third too dark, so that relit under a true light
// they are too dark (bench/RESULTS.md, session 35). Outdoors, what lies below the horizon is the ground, a
// Lambertian surface facing up: its radiance is r x E(up), r = rho/pi its reflectance per unit irradiance.
// This prior pulls the light's radiance in a fixed set of downward directions towards that, with the target
// held fixed (it moves the lower half, not the ground the photos show).
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// The directions the prior samples: straight down, and rings of eight at 30 and 60 degrees below the
// horizon of `up` (unit).
inline constexpr int kGroundLightDirections = 17;
void ground_light_directions(Vec3d up, Vec3d out[kGroundLightDirections]);

// The ground's radiance per unit irradiance, per channel, in the model's units, from the activated albedo of
// its surfels (model/ground_albedo.h; 0 when the model has none):
// - assumed_albedo = 0: the model's own, albedo^2.2 (the albedo multiplies the display colour and holds the
//   1/pi: shading/surfel_shading.h). Its level follows the gauge between albedo and light, which only the
//   sky pixels pin (sky_pins_light); with a free sky it floats with the albedo's level.
// - assumed_albedo > 0: that physical albedo rho (a typical ground's) over pi, in the colour of the model's
//   ground (its albedo^2.2 over the channels' mean; grey without a ground). Free of the gauge: the lower half
//   then follows E(up) whatever the albedo's level.
Vec3d ground_reflectance(Vec3f ground_albedo, double assumed_albedo);

// Mean over the directions and the channels of (L(d) - r E(up))^2, in the units of l_+ (a scale-free form,
// divided by the target's size, blew up while the lights start near 0). `env` is the photo's radiance SH,
// `reflectance` r from ground_reflectance. Returns the unweighted value; adds weight x its gradient with
// respect to env (the target held fixed) into g_env. 0, and no gradient, when r is 0 in every channel.
double ground_light_prior(const ShCoeffs<float>& env, Vec3f up, Vec3d reflectance, double weight,
                          ShCoeffs<float>& g_env);

}  // namespace lumigauss
