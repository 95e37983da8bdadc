#pragma once
// A prior on each photo's sky where the photo did not see it. A photo's sky (light + degree-4 residual,
// sky_colour.h) is fitted only to the directions its own sky pixels cover; relit from a new viewpoint under
// that photo's light, the rest of the hemisphere showed whatever the fit left there, often black
// (bench/RESULTS.md, session 39: a third of the 60 training lights of plaza). The prior pulls the sky's
// radiance at fixed directions over the upper hemisphere that the photo's camera does not see towards the
// mean radiance of the photo's sky pixels: the seen sky is still fitted by its pixels, the unseen sky becomes
// the seen sky's mean instead of whatever the fit left there.
#include <optional>
#include <span>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss {

// The prior's directions (one per ~320 square degrees: enough for a degree-4 sky) and the fewest sky pixels
// that give a photo a target (fewer: the photo goes without the prior).
inline constexpr int kSkyHemisphereDirections = 64;
inline constexpr int kSkyHemisphereMinPixels = 64;

// Directions in the hemisphere above the unit `up` (up . d > 0), `count` of them on a Fibonacci spiral:
// each covers about the same solid angle.
std::vector<Vec3f> upper_hemisphere_directions(Vec3f up, int count);

// The directions a camera does not see (outside its image, or behind it): where the prior acts. Inside the
// image the photo's own sky pixels say what the sky is, and a pull towards their mean would only blur them.
std::vector<Vec3f> directions_out_of_view(std::span<const Vec3f> directions, const Camera& camera);

// The mean linear radiance of the photo's sky: the photo (display space, 3 per pixel) averaged over the
// pixels whose sky weight is > 0.5 and that are not saturated (a sun's glare spread over the hemisphere would
// light all of it), then raised to 2.2. nullopt when fewer than `min_pixels` pixels qualify.
std::optional<Vec3f> mean_sky_radiance(std::span<const float> photo, std::span<const float> sky_weight,
                                       int min_pixels);

// The prior's loss: the mean over `directions` and channels of (L_c(d) + R_c(d) - target_c)^2, where L is
// the photo's light `env` and R its sky residual. Only the residual moves (the light is the surfels'):
// adds weight * dLoss/dR into g_residual. Returns the unweighted loss.
double sky_hemisphere_prior(std::span<const Vec3f> directions, const ShCoeffs<float>& env,
                            const Sh4Coeffs<float>& residual, Vec3f target, double weight,
                            Sh4Coeffs<float>& g_residual);

}  // namespace lumigauss
