#pragma once
// The files written per rendered frame (STEM = the view's image name without extension, or the frame name):
//   STEM_shadowed.png     shadowed colour, clamped to [0, 1]
//   STEM_unshadowed.png   unshadowed colour, clamped
//   STEM_albedo.png       albedo max(0, Y00 a + 0.5) as rasterised (the model's gamma-2.2 domain), clamped
//   STEM_normal.png       world normal (n / |n| + 1) / 2, black where nothing is rendered
//   STEM_shadow.png       the official shadow image 1 - clamp(luma(I_unshadowed - I_shadowed), 0, 1000)
//                         (relit_render.h; 1 = no shadow), clamped
//   STEM_irradiance.png, STEM_irradiance_unshadowed.png
//                         the rasterised post-gamma intensity max(H, 1e-5)^(1/2.2) (shadowed, unshadowed),
//                         both divided by their common maximum when it exceeds 1 (the official visualisation)
//   STEM_irradiance.exr   shadowed intensity, unclamped, unnormalised
//   STEM_depth.exr        expected depth (depth / alpha; 0 where alpha <= 1e-6)
//   STEM_alpha.png        alpha
// With `exr`, also unclamped float EXRs of shadowed, unshadowed, albedo, irradiance_unshadowed, shadow and
// the unit world normal (in [-1, 1]). Every file is written atomically.
#include <string>
#include <vector>

#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

struct RelitOutputs {
    bool shadowed = true, unshadowed = true, albedo = true, normal = true, shadow = true, irradiance = true,
         depth = true, alpha = true;
    bool exr = false;
    bool has_background = false;  // composite colour and albedo over `background` (else black)
    Vec3f background{};
    bool sky_background = false;  // composite colour over the light's sky (relit_sky.h) instead
};

// "all" or a comma-separated subset of shadowed, unshadowed, albedo, normal, shadow, irradiance, depth,
// alpha. Throws Error naming the unknown entry.
RelitOutputs parse_relit_outputs(const std::string& list);

// dir / (stem + suffix) as a string ("a/b" stems make sub-folders).
std::string relit_path(const std::string& dir, const std::string& stem, const std::string& suffix);

// Writes the selected files of one frame from the RelitRenderer output (creating the sub-folders of the
// stem) and returns their paths.
// `sky` (3 channels, the frame's size) is the background of the colour maps when outputs.sky_background.
std::vector<std::string> write_relit_frame(const std::string& dir, const std::string& stem,
                                           const RasterImages<float>& raster, const RelitOutputs& outputs,
                                           const Image* sky = nullptr);

}  // namespace lumigauss
