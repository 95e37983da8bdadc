// meta.json of a synthetic dataset: the keys of data/plaza's meta.json (per image: name, image_id, split,
// condition, exposure, fx fy cx cy, width height, c2w, has_transients, n_transients), so one evaluation
// path reads both. No timings: the file must be byte-identical for a given seed.
#include <nlohmann/json.hpp>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/synth/dataset_writer.h"

namespace lumigauss::synth {

namespace {

using Json = nlohmann::ordered_json;

Json vec(Vec3d v) {
    return Json::array({v.x, v.y, v.z});
}

Json sh_rows(const ShCoeffs<double>& sh) {
    Json rows = Json::array();
    for (const Vec3d& c : sh.c) rows.push_back(vec(c));
    return rows;
}

Json condition_json(const LightCondition& c) {
    const Vec3d up{0, 0, 1};
    Json j;
    j["id"] = c.id;
    j["type"] = "analytic_sky";
    j["split"] = c.split;
    j["env_exr"] = "env/" + c.id + ".exr";
    j["env_png"] = "env/" + c.id + ".png";
    j["sh"] = "env/" + c.id + "_sh.txt";
    j["overcast"] = c.overcast;
    j["strength"] = c.strength;
    j["sun_elevation_deg"] = sun_elevation_deg(c);
    j["sun_azimuth_deg"] = sun_azimuth_deg(c);
    j["sun_size_deg"] = kSunDiameterDeg;
    j["sun_dir_world"] = vec(c.sun_dir);
    j["sun_power_rgb"] = vec(c.sun_power);
    j["sun_env_pixel_rowcol"] = Json::array({c.sun_row, c.sun_col});
    // Exact irradiance of an unoccluded up-facing surface in this lighting, and its order-2 SH estimate.
    j["irradiance_up_numeric"] = vec(sky_irradiance(c, up) + sun_irradiance(c, up));
    j["irradiance_up_sh"] = vec(irradiance(environment_sh(c), up));
    j["sky_sh"] = sh_rows(c.sky_sh);
    return j;
}

Json image_json(const Photo& p, const std::string& condition) {
    Json j;
    j["name"] = p.name;
    j["image_id"] = p.image_id;
    j["split"] = p.train ? "train" : "test";
    j["condition"] = condition;
    j["exposure"] = p.exposure;
    j["fx"] = p.camera.fx;
    j["fy"] = p.camera.fy;
    j["cx"] = p.camera.cx;
    j["cy"] = p.camera.cy;
    j["width"] = p.camera.width;
    j["height"] = p.camera.height;
    j["c2w"] = camera_to_world(p.camera);
    j["has_transients"] = p.n_transients > 0;
    j["n_transients"] = p.n_transients;
    return j;
}

}  // namespace

void write_meta_json(const std::string& dir, const MetaInputs& in) {
    const SynthOptions& o = *in.options;
    Json j;
    j["scene"] = o.scene;
    j["generator"] = "lumigauss synth (CPU ray tracer)";
    j["seed"] = o.seed;
    j["width"] = o.width;
    j["height"] = o.height;
    j["samples_per_pixel_max"] = o.samples_per_side * o.samples_per_side;
    j["world_frame"] = "right-handed, +Z up, metres; ground plane z=0; the landmark's front faces -Y";
    j["camera_convention"] =
        "OpenCV/COLMAP: camera x right, y down, z forward; c2w maps camera coords to world; pixel (u,v) with "
        "u "
        "right, v down, origin at the top-left image corner (pixel centres at +0.5)";
    j["pixel_formula"] = "pixel_8bit = round(255 * srgb_encode(clip(exposure * radiance, 0, 1)))";
    j["shading_formula"] =
        "radiance = albedo/pi * (E_sky(n) + V_sun * sun_power * max(0, n.s)); E_sky = Ramamoorthi-Hanrahan "
        "irradiance of sky_sh (no sky occlusion, no interreflection); V_sun traced (hard shadows)";
    j["env_convention"] =
        "equirect, H=64 rows x W=128 cols, row 0 = zenith (+Z). For pixel (row i, col j): theta=pi*(i+0.5)/H "
        "(polar angle from +Z), phi=2*pi*(0.5-(j+0.5)/W); d=(sin(theta)cos(phi), sin(theta)sin(phi), "
        "cos(theta)). Image centre column looks along +X, a quarter image to the left is +Y, a quarter to "
        "the "
        "right is -Y, the left/right edges are -X.";
    j["sh_convention"] =
        "9 lines of R G B: radiance L_lm; order (0,0),(1,-1),(1,0),(1,1),(2,-2),(2,-1),(2,0),(2,1),(2,2); "
        "Y00=0.282095, Y1-1=0.488603y, Y10=0.488603z, Y11=0.488603x, Y2-2=1.092548xy, Y2-1=1.092548yz, "
        "Y20=0.315392(3z^2-1), Y21=1.092548xz, Y22=0.546274(x^2-y^2); env/COND_sh.txt = sky_sh + SH of the "
        "sun disc";
    j["building_bbox"] = Json::array({vec(in.landmark->bbox_lo), vec(in.landmark->bbox_hi)});
    j["ground"] = "plane z=0 spanning [-300,300]^2";
    j["scene_diag"] = in.scene_diag;
    j["point_noise_sigma_per_axis"] = in.noise_sigma;
    Json conditions = Json::array();
    for (const LightCondition& c : *in.conditions) conditions.push_back(condition_json(c));
    j["conditions"] = conditions;
    Json images = Json::array();
    for (const Photo& p : *in.photos)
        images.push_back(image_json(p, (*in.conditions)[std::size_t(p.condition)].id));
    j["images"] = images;
    j["n_points3D"] = in.n_points;
    if (in.gt_surfels && in.gt_surfels->model.size() > 0) {
        const GtSurfels& g = *in.gt_surfels;
        j["gt_surfels"] = {{"path", "gt/surfels.ply"},
                           {"count", g.model.size()},
                           {"cell_m", g.cell},
                           {"ground_cell_m", g.ground_cell},
                           {"ground_near_radius_m", g.near_radius},
                           {"colour", "SH degree 0, 0.5 + 0.28209479 * f_dc = linear albedo"}};
    }
    write_file_atomically(dir + "/meta.json", j.dump(1) + "\n");
}

}  // namespace lumigauss::synth
