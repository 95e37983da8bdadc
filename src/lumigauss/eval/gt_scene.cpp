#include "lumigauss/eval/gt_scene.h"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "lumigauss/io/image_metrics.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

Json parse_json_file(const std::string& path) {
    Json j = Json::parse(read_text_file(path), nullptr, false);
    if (j.is_discarded()) fail_in_file(path, "not valid JSON");
    return j;
}

Image multiply_masks(const Image& a, const Image& b) {
    Image out = a;
    for (std::size_t p = 0; p < out.pixels.size(); ++p) out.pixels[p] *= b.pixels[p];
    return out;
}

}  // namespace

const GtImageMeta* GtSceneMeta::find(const std::string& name) const {
    for (const GtImageMeta& m : images)
        if (m.name == name) return &m;
    return nullptr;
}

std::string GtSceneMeta::sh_path(const std::string& condition) const {
    const auto it = condition_sh.find(condition);
    if (it != condition_sh.end()) return (fs::path(root) / it->second).string();
    return (fs::path(root) / "env" / (condition + "_sh.txt")).string();
}

GtSceneMeta load_gt_scene_meta(const std::string& scene_root) {
    GtSceneMeta meta;
    meta.root = scene_root;
    meta.meta_path = (fs::path(scene_root) / "meta.json").string();
    if (!fs::exists(meta.meta_path))
        fail_in_file(meta.meta_path,
                     "missing: the gt-env protocol needs a scene with ground-truth lighting (meta.json, "
                     "env/COND_sh.txt), as data/plaza or `lumigauss synth` write");
    const Json j = parse_json_file(meta.meta_path);
    if (!j.is_object() || !j.contains("images") || !j["images"].is_array())
        fail_in_file(meta.meta_path, "expected a JSON object with an \"images\" array");
    std::size_t index = 0;
    for (const Json& e : j["images"]) {
        const std::string where = "images[" + std::to_string(index++) + "]";
        if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("condition") ||
            !e["condition"].is_string())
            fail_in_file(meta.meta_path, where + " needs a string \"name\" and a string \"condition\"");
        GtImageMeta m;
        m.name = e["name"].get<std::string>();
        m.condition = e["condition"].get<std::string>();
        if (e.contains("split")) {
            if (!e["split"].is_string()) fail_in_file(meta.meta_path, where + ": \"split\" must be a string");
            m.split = e["split"].get<std::string>();
        }
        if (e.contains("exposure")) {
            if (!e["exposure"].is_number() || !(e["exposure"].get<double>() > 0))
                fail_in_file(meta.meta_path, where + ": \"exposure\" must be a positive number");
            m.exposure = e["exposure"].get<double>();
        }
        meta.images.push_back(std::move(m));
    }
    if (j.contains("conditions") && j["conditions"].is_array())
        for (const Json& c : j["conditions"])
            if (c.is_object() && c.contains("id") && c["id"].is_string() && c.contains("sh") &&
                c["sh"].is_string())
                meta.condition_sh[c["id"].get<std::string>()] = c["sh"].get<std::string>();
    return meta;
}

ShCoeffs<double> load_condition_sh(const GtSceneMeta& meta, const std::string& condition) {
    const std::string path = meta.sh_path(condition);
    if (!fs::exists(path))
        fail_in_file(path, "missing: the true SH of lighting condition '" + condition + "' (named in " +
                               meta.meta_path + ")");
    return read_sh_text(path);
}

std::string gt_image_path(const std::string& root, const std::string& kind, const std::string& image_name) {
    fs::path p = fs::path(root) / "gt" / kind / image_name;
    p.replace_extension(".png");
    return p.string();
}

Image load_gt_image(const std::string& path, int width, int height, int channels) {
    Image im = to_channels(read_image(path), channels);
    if (im.width != width || im.height != height) im = resize_area(im, width, height);
    return im;
}

Image evaluation_mask(const GtSceneMeta& meta, const Dataset& scene, const View& v, bool& has_gt_mask) {
    const std::string gt_mask_path = gt_image_path(meta.root, "mask", v.name);
    has_gt_mask = fs::exists(gt_mask_path);
    const Image scene_mask = binarize_mask(scene.load_mask(v), 0.5f);
    return has_gt_mask
               ? multiply_masks(
                     official_eval_mask(load_gt_image(gt_mask_path, v.camera.width, v.camera.height, 1)),
                     scene_mask)
               : official_eval_mask(scene_mask);
}

ShCoeffs<float> scaled_true_env(const GtSceneMeta& meta, const GtImageMeta& im,
                                const std::array<double, 3>& scale) {
    const ShCoeffs<double> truth = load_condition_sh(meta, im.condition);
    ShCoeffs<float> env;
    for (int j = 0; j < kShCount; ++j)
        for (int c = 0; c < 3; ++c)
            env.c[j][c] = float(truth.c[j][c] * (scale[std::size_t(c)] * im.exposure));
    return env;
}

const Image* TruePanoramas::find(const std::string& condition) {
    auto [it, added] = cache_.try_emplace(condition);
    if (added)
        for (const char* ext : {".exr", ".hdr"})
            if (const std::string path = meta_.root + "/env/" + condition + ext; fs::exists(path)) {
                it->second = read_image(path);
                break;
            }
    return it->second ? &*it->second : nullptr;
}

}  // namespace lumigauss
