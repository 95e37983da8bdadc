#pragma once
// The sky behind a relit frame (`render RUN --background sky`), in the model's display space
// (shading/sky_colour.h): a panorama light's own pixels along each pixel's ray, so that the sky shows what
// the panorama shows rather than its degree-2 SH; any other light's SH (plus a training photo's sky residual,
// when the run learned one and the light is not turned).
#include "lumigauss/io/camera.h"
#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"
#include "lumigauss/shading/sky_image.h"

namespace lumigauss {

struct PanoramaSky {
    const Image* pixels = nullptr;    // equirectangular radiance (shading/envmap.h)
    Mat3d frame = Mat3d::identity();  // world direction = frame * panorama direction
    Vec3d factor{1, 1, 1};            // the light's scale per channel (--exposure, --match-exposure)
    Vec3d up{0, 0, 1};
    double degrees = 0;     // the environment turned about `up` (counter-clockwise seen from above)
    SkyHorizon horizon;     // where the sky ends below the horizon (none by default: drawn as it is)
    Vec3f ground{0, 0, 0};  // display colour drawn where the sky has faded (horizon_ground_colour)
};

// sky_visibility * sky_channel(factor * pano(R(-degrees) d)) + (1 - sky_visibility) * ground per pixel,
// bilinear in the panorama (columns wrap).
Image panorama_sky_image(const Camera& camera, const PanoramaSky& sky);

// A point of an equirectangular image, bilinear; columns wrap around, rows clamp.
Vec3d sample_equirect(const Image& pano, double row, double col);

}  // namespace lumigauss
