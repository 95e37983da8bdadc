#pragma once
// What the viewer's page needs besides the surfels (GET /scene.json): the lightings to choose from, the up
// axis, an initial camera and the model's extent. JSON, for example
//   {"format": "lumigauss-viewer-scene", "version": 1, "surfels": 200000,
//    "up": [0, 0, 1], "up_name": "+z", "e1": [1, 0, 0], "e2": [0, 1, 0],
//    "centre": [x, y, z], "radius": r,
//    "camera": null | {"width": W, "height": H, "fx": .., "fy": .., "cx": .., "cy": ..,
//                      "R": [[..], [..], [..]], "t": [..]},          (cameras/camera_json.h conventions)
//    "lights": [{"name": "IMG_0001.jpg", "kind": "training photo", "sh": [[R, G, B] x 9],
//                "sky_residual": [[R, G, B] x 25]}, ...],     (sky_residual only where the light has one)
//    "initial_light": 0, "sky_background": bool, "sky_horizon": null | {..},
//    "side_rule": null | {"up": [x, y, z], "grazing_degrees": d}}   (shading/surfel_side.h; null: official)
// Lights in order: those given with --light, then every training photo's learned lighting (embedding
// order), then "uniform" (constant radiance with irradiance 1 everywhere, for inspecting albedo and
// geometry). A training photo's light of a run with sky residuals, and an SH file with "#sky" rows, carry
// the sky's residual (degree 4, shading/sh_degree4.h order): the sky is drawn from light + residual
// (shading/sky_colour.h), never the shading. SH are radiance L_lm in the world frame (shading/sh.h order).
// up, e1, e2 form the right-handed orbit frame of cameras/orbit.h (azimuth a = cos a e1 + sin a e2). centre
// is the per-axis median of the surfel positions, radius the 90th percentile of their distance to it (robust
// to stray surfels).
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss::view {

struct ViewerLight {
    std::string name;
    std::string kind;  // light_kind_name(), or "uniform"
    ShCoeffs<double> sh;
    std::optional<Sh4Coeffs<float>> sky_residual;  // drawn in the sky only
};

struct ViewerScene {
    std::size_t surfels = 0;
    Vec3d up{0, 0, 1};
    Vec3d centre{};
    double radius = 1;
    std::optional<Camera> camera;  // the initial view when known (--scene, --camera)
    std::vector<ViewerLight> lights;
    bool sky_background = false;  // the run was trained with its sky drawn behind the surfels
    SkyHorizon sky_horizon;       // where that sky ends below the horizon (no fade: nowhere)
    SurfelSideRule side_rule;     // which side of a surfel a camera sees, as trained (TrainedRun's)
};

// The uniform environment: radiance 1 / pi in every direction, so irradiance(L, n) = 1 for every n.
ShCoeffs<double> uniform_environment();

// Builds the description from the run, the --light lights (already resolved, in order) and the options.
ViewerScene describe_scene(const TrainedRun& run, const std::vector<ResolvedLight>& extra_lights, Vec3d up,
                           std::optional<Camera> camera);

// The JSON text above.
std::string scene_json(const ViewerScene& scene);

}  // namespace lumigauss::view
