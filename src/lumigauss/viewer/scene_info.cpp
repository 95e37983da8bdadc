#include "lumigauss/viewer/scene_info.h"

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "lumigauss/cameras/orbit.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/shading/irradiance.h"

namespace lumigauss::view {
namespace {

using nlohmann::json;

json vec_json(Vec3d v) {
    return json::array({v.x, v.y, v.z});
}

json sh_json(const ShCoeffs<double>& sh) {
    json rows = json::array();
    for (int k = 0; k < kShCount; ++k) rows.push_back(vec_json(sh.c[k]));
    return rows;
}

json camera_json(const Camera& c) {
    json r = json::array();
    for (int i = 0; i < 3; ++i) r.push_back(vec_json(c.rotation.row(i)));
    return {{"width", c.width}, {"height", c.height}, {"fx", c.fx}, {"fy", c.fy},
            {"cx", c.cx},       {"cy", c.cy},         {"R", r},     {"t", vec_json(c.translation)}};
}

// Centre and radius of the bulk of the surfels (see the header); a unit sphere at the origin when empty.
void model_extent(const SurfelModel& model, ViewerScene& scene) {
    const std::vector<float>& xyz = model.param(ModelParam::Xyz);
    const std::size_t n = model.size();
    if (n == 0) return;
    std::vector<Vec3f> points(n);
    for (std::size_t i = 0; i < n; ++i) points[i] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    scene.centre = point_cloud_centre(points);
    std::vector<double> dist(n);
    for (std::size_t i = 0; i < n; ++i) dist[i] = length(points[i].cast<double>() - scene.centre);
    const auto at = dist.begin() + std::ptrdiff_t(std::min(n - 1, n * 9 / 10));
    std::nth_element(dist.begin(), at, dist.end());
    scene.radius = *at > 1e-9 ? *at : 1.0;
}

std::string light_name(const ResolvedLight& light) {
    if (light.kind == LightKind::Photo) return light.source;
    return std::filesystem::path(light.source).filename().string();
}

}  // namespace

ShCoeffs<double> uniform_environment() {
    return uniform_irradiance_environment<double>();
}

ViewerScene describe_scene(const TrainedRun& run, const std::vector<ResolvedLight>& extra_lights, Vec3d up,
                           std::optional<Camera> camera) {
    ViewerScene scene;
    scene.surfels = run.model.size();
    scene.up = up;
    scene.camera = std::move(camera);
    scene.sky_background = run.sky_background;
    scene.sky_horizon = run.sky_horizon;
    scene.side_rule = run.side_rule;
    model_extent(run.model, scene);
    for (const ResolvedLight& l : extra_lights)
        scene.lights.push_back({light_name(l), light_kind_name(l.kind), l.sh, l.sky_residual});
    for (std::size_t i = 0; i < run.image_names.size(); ++i) {
        std::optional<Sh4Coeffs<float>> residual;
        if (!run.sky_residuals.empty()) residual = run.sky_residuals.get(int(i));
        scene.lights.push_back(
            {run.image_names[i], light_kind_name(LightKind::Photo), run.learned_sh(int(i)), residual});
    }
    scene.lights.push_back({"uniform", "uniform", uniform_environment(), std::nullopt});
    return scene;
}

std::string scene_json(const ViewerScene& scene) {
    Vec3d e1, e2;
    orbit_basis(scene.up, e1, e2);
    json lights = json::array();
    for (const ViewerLight& l : scene.lights) {
        json light = {{"name", l.name}, {"kind", l.kind}, {"sh", sh_json(l.sh)}};
        if (l.sky_residual) {
            json rows = json::array();
            for (const Vec3f& row : l.sky_residual->c) rows.push_back(vec_json(row.cast<double>()));
            light["sky_residual"] = rows;
        }
        lights.push_back(light);
    }
    json j = {{"format", "lumigauss-viewer-scene"},
              {"version", 1},
              {"surfels", scene.surfels},
              {"up", vec_json(scene.up)},
              {"up_name", up_axis_name(scene.up)},
              {"e1", vec_json(e1)},
              {"e2", vec_json(e2)},
              {"centre", vec_json(scene.centre)},
              {"radius", scene.radius},
              {"camera", scene.camera ? camera_json(*scene.camera) : json(nullptr)},
              {"lights", lights},
              {"initial_light", 0},
              {"sky_background", scene.sky_background}};
    const SkyHorizon& h = scene.sky_horizon;
    j["sky_horizon"] = h.fade_degrees > 0 ? json{{"up", vec_json(h.up.cast<double>())},
                                                 {"start_degrees", h.start_degrees},
                                                 {"fade_degrees", h.fade_degrees},
                                                 {"ground_albedo", vec_json(h.ground_albedo.cast<double>())}}
                                          : json(nullptr);
    const SurfelSideRule& s = scene.side_rule;
    j["side_rule"] = s.active()
                         ? json{{"up", vec_json(s.up.cast<double>())}, {"grazing_degrees", s.grazing_degrees}}
                         : json(nullptr);
    return j.dump();
}

}  // namespace lumigauss::view
