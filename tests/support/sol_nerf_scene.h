#pragma once
// A tiny NeRF-OSR-layout scene for the sol-nerf protocol tests (eval_sol_nerf_test, cli_eval_sol_nerf_test):
// a street corner of surfels in a y-down world (COLMAP's up is -y), test photos rendered by the model itself
// under ground-truth panoramas turned by KNOWN search angles, the panoramas as LDR PNGs in
// final/ENV_MAP_CC/<session>/, an evaluation mask, and a config in the format of configs/sol_nerf.
//
//   <dir>/scene/final/{train,test}/{rgb,pose,intrinsics,mask}/...
//   <dir>/scene/final/ENV_MAP_CC/<session>/<timestamp>.png      (1200 x 600: exercises the 1000 x 500 resize)
//   <dir>/masks/<stem>.png                                      (half the photo's size: exercises the resize)
//   <dir>/sol.json
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "lumigauss/eval/official_sh_projection.h"
#include "lumigauss/eval/sol_nerf.h"
#include "lumigauss/io/image.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/render_model.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/train/gaussian_model.h"

namespace lumigauss::testing {

namespace sol_scene_detail {

namespace fs = std::filesystem;

inline void write_text(const std::string& path, const std::string& text) {
    fs::create_directories(fs::path(path).parent_path());
    std::ofstream(path) << text;
}

// A unit quaternion (w first) whose rotation takes +z to the unit vector n.
inline Vec4f quaternion_for_normal(Vec3d n) {
    const Vec3d z{0, 0, 1};
    const double c = dot(z, n);
    if (c < -0.999999) return {0, 1, 0, 0};  // half turn about x
    const Vec3d axis = cross(z, n);
    const double s = length(axis), angle = std::atan2(s, c);
    if (s < 1e-12) return {1, 0, 0, 0};
    const Vec3d a = axis / s;
    const double h = std::sin(angle / 2);
    return {float(std::cos(angle / 2)), float(a.x * h), float(a.y * h), float(a.z * h)};
}

struct Wall {
    Vec3d origin, u, v, normal;  // surfels at origin + i du u + j dv v
    int nu, nv;
    Vec3d albedo;
};

}  // namespace sol_scene_detail

// Ground (normal -y, "up"), a back wall facing the camera and two side walls facing each other, each with its
// own albedo; transfer sets are the cosine lobes of their side (unoccluded: shadowed == unshadowed).
inline GaussianModel street_model() {
    using namespace sol_scene_detail;
    const Wall walls[] = {
        {{-2, 1, 2}, {0.25, 0, 0}, {0, 0, 0.25}, {0, -1, 0}, 17, 21, {0.5, 0.5, 0.5}},
        {{-2, -2, 7}, {0.25, 0, 0}, {0, 0.25, 0}, {0, 0, -1}, 17, 13, {0.6, 0.4, 0.3}},
        {{-2, -2, 2}, {0, 0, 0.25}, {0, 0.25, 0}, {1, 0, 0}, 21, 13, {0.3, 0.5, 0.6}},
        {{2, -2, 2}, {0, 0, 0.25}, {0, 0.25, 0}, {-1, 0, 0}, 21, 13, {0.5, 0.5, 0.3}},
    };
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (const Wall& w : walls)
        for (int i = 0; i < w.nu; ++i)
            for (int j = 0; j < w.nv; ++j) {
                const Vec3d p = w.origin + double(i) * w.u + double(j) * w.v;
                for (int k = 0; k < 3; ++k) raw[int(ModelParam::Xyz)].push_back(float(p[k]));
                const Vec4f q = quaternion_for_normal(w.normal);
                for (int k = 0; k < 4; ++k) raw[int(ModelParam::Rotation)].push_back(q[k]);
                for (int k = 0; k < 2; ++k) raw[int(ModelParam::Scaling)].push_back(std::log(0.15f));
                raw[int(ModelParam::Opacity)].push_back(inverse_sigmoid(0.95f));
                for (int c = 0; c < 3; ++c)
                    raw[int(ModelParam::Albedo)].push_back(float((w.albedo[c] - 0.5) / sh_const::kY00));
                double pos[kShCount], neg[kShCount];
                cosine_lobe_sh(w.normal, pos);
                cosine_lobe_sh(-w.normal, neg);
                for (int k = 0; k < kShCount; ++k)
                    for (int c = 0; c < 3; ++c) {
                        raw[int(ModelParam::TransferPositive)].push_back(float(pos[k]));
                        raw[int(ModelParam::TransferNegative)].push_back(float(neg[k]));
                    }
            }
    return GaussianModel::from_raw(std::move(raw), 1.0);
}

// An LDR sky: bluish above the horizon row, dark below, and a saturated sun disk (value 1.0, boosted by the
// protocol's fake HDR) around the pixel (sun_row, sun_col), 8 degrees in radius.
inline Image sun_panorama(int width, int sun_row, int sun_col) {
    const int height = width / 2;
    Image pano(width, height, 3);
    const Vec3d sun = official_panorama_direction(sun_row, sun_col, width);
    const double cos_radius = std::cos(8.0 * std::numbers::pi / 180.0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const double up = 1.0 - 2.0 * y / height;  // 1 at the top row, 0 at the horizon
            Vec3d v =
                up > 0 ? Vec3d{0.2 + 0.1 * up, 0.25 + 0.1 * up, 0.35 + 0.15 * up} : Vec3d{0.12, 0.1, 0.08};
            if (dot(official_panorama_direction(y, x, width), sun) > cos_radius) v = {1, 1, 1};
            for (int c = 0; c < 3; ++c) pano.at(x, y, c) = float(v[c]);
        }
    return pano;
}

inline void write_matrix(const std::string& path, const std::vector<double>& m) {
    std::string text;
    for (std::size_t i = 0; i < m.size(); ++i) text += std::to_string(m[i]) + (i % 4 == 3 ? "\n" : " ");
    sol_scene_detail::write_text(path, text);
}

struct SolNerfTestImage {
    std::string config_name;  // as the config names it (.JPG), while the photo is a PNG
    std::string stem, session;
    int sun_row, sun_col;
    double range_pi[2];
    std::size_t true_index;
    bool eval_mask;  // a configured evaluation mask (else the scene's own mask)
};

struct SolNerfTestScene {
    std::string dir, scene, config, mask_root;
    std::vector<SolNerfTestImage> images;
    int angles = kSolNerfDefaultAngles;
};

inline Camera sol_test_camera() {
    Camera cam;  // camera-to-world identity: looking along +z with y down, like NeRF-OSR's OpenCV axes
    cam.width = 64, cam.height = 48, cam.fx = cam.fy = 50, cam.cx = 32, cam.cy = 24;
    return cam;
}

inline void write_view(const std::string& split_dir, const std::string& stem, const Image& photo) {
    namespace fs = std::filesystem;
    fs::create_directories(split_dir + "/rgb");
    write_png(split_dir + "/rgb/" + stem + ".png", photo, 16);
    write_matrix(split_dir + "/pose/" + stem + ".txt", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1});
    const Camera c = sol_test_camera();
    write_matrix(split_dir + "/intrinsics/" + stem + ".txt",
                 {c.fx, 0, c.cx, 0, 0, c.fy, c.cy, 0, 0, 0, 1, 0, 0, 0, 0, 1});
    fs::create_directories(split_dir + "/mask");
    write_png(split_dir + "/mask/" + stem + ".png", Image(c.width, c.height, 1, 1.0f));
}

inline std::string sol_test_config_json(const SolNerfTestScene& s) {
    std::string images;
    for (const SolNerfTestImage& im : s.images) {
        images += std::string(images.empty() ? "" : ",\n") + "    {\"name\": \"" + im.config_name +
                  "\", \"env_map\": \"ENV_MAP_CC/" + im.session + "/20210801_082411.png\", " +
                  (im.eval_mask ? "\"mask\": \"" + im.stem + ".png\", " : "") + "\"y_range_pi\": [" +
                  std::to_string(im.range_pi[0]) + ", " + std::to_string(im.range_pi[1]) + "]}";
    }
    return "{\n  \"_doc\": \"test scene\",\n  \"scene\": \"street\",\n  \"angles\": " +
           std::to_string(s.angles) +
           ",\n  \"defaults\": {\"rotation_deg\": {\"x\": -90}, \"hdr_threshold\": 0.99, \"hdr_scale\": "
           "20},\n"
           "  \"images\": [\n" +
           images + "\n  ]\n}\n";
}

// Writes everything under `dir` (an existing, empty folder) and returns where it is.
inline SolNerfTestScene write_sol_nerf_test_scene(const std::string& dir, const GaussianModel& model) {
    namespace fs = std::filesystem;
    SolNerfTestScene s;
    s.dir = dir, s.scene = dir + "/scene", s.config = dir + "/sol.json", s.mask_root = dir + "/masks";
    s.images = {
        {"01-08_07_30_IMG_0001.JPG", "01-08_07_30_IMG_0001", "01-08_07_30", 170, 360, {-0.5, 0.5}, 37, true},
        {"02-08_12_00_IMG_0002.png", "02-08_12_00_IMG_0002", "02-08_12_00", 120, 900, {0.2, 1.2}, 12, false}};
    const std::string final_dir = s.scene + "/final";
    const Camera cam = sol_test_camera();
    for (const SolNerfTestImage& im : s.images) {
        const std::string env_dir = final_dir + "/ENV_MAP_CC/" + im.session;
        fs::create_directories(env_dir);
        write_png(env_dir + "/20210801_082411.png", sun_panorama(1200, im.sun_row, im.sun_col));
        const OfficialEnvironment env = official_environment_sh(env_dir + "/20210801_082411.png", 0.99, 20);
        SolNerfImageConfig cfg;
        cfg.rotation_deg[0] = -90;
        const double b = sol_nerf_angles(im.range_pi[0] * std::numbers::pi, im.range_pi[1] * std::numbers::pi,
                                         s.angles)[im.true_index];
        const ShCoeffs<float> light = sol_nerf_environment(env.sh, cfg, b).cast<float>();
        Image photo(cam.width, cam.height, 3);
        photo.pixels = render_with_environment(model, cam, light, ShadingMode::Shadowed).color;
        for (float& v : photo.pixels) v = std::clamp(v, 0.0f, 1.0f);
        write_view(final_dir + "/test", im.stem, photo);
        if (im.eval_mask) {
            Image mask(cam.width / 2, cam.height / 2, 1, 1.0f);
            for (int y = 0; y < 6; ++y)
                for (int x = 0; x < 8; ++x) mask.at(x, y, 0) = 0.0f;
            fs::create_directories(s.mask_root);
            write_png(s.mask_root + "/" + im.stem + ".png", mask);
        }
    }
    write_view(final_dir + "/train", "03-08_09_00_IMG_0003", Image(cam.width, cam.height, 3, 0.5f));
    sol_scene_detail::write_text(s.config, sol_test_config_json(s));
    return s;
}

}  // namespace lumigauss::testing
