#pragma once
// A "photo" made by the model itself: the render under a light, clamped to [0, 1] as a photo would be
// (fit-light and holdout tests fit such photos back).
#include <algorithm>

#include "lumigauss/io/image.h"
#include "lumigauss/model/render_model.h"

namespace lumigauss::testing {

inline Image clamped_render(const SurfelModel& model, const Camera& camera, const ShCoeffs<double>& light,
                            ShadingMode mode = ShadingMode::Shadowed) {
    const RasterImages<float> img = render_with_environment(model, camera, light.cast<float>(), mode);
    Image out(camera.width, camera.height, 3);
    for (std::size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = std::clamp(img.color[i], 0.0f, 1.0f);
    return out;
}

}  // namespace lumigauss::testing
