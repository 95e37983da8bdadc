#include "lumigauss/eval/sol_nerf_config.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>

#include "lumigauss/io/text_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr const char* kImageKeys[] = {"name",          "env_map",   "mask",      "rotation_deg",
                                      "hdr_threshold", "hdr_scale", "y_range_pi"};

bool is_comment(const std::string& key) {
    return !key.empty() && key[0] == '_';
}

// Throws for a key that is neither a comment nor one of `allowed`.
template <std::size_t N>
void check_keys(const Json& object, const char* const (&allowed)[N], const std::string& path,
                const std::string& where) {
    for (const auto& [key, value] : object.items()) {
        if (is_comment(key)) continue;
        bool known = false;
        for (const char* a : allowed) known = known || key == a;
        if (!known) fail_in_file(path, where + ": unknown key \"" + key + "\"");
    }
}

double finite_number(const Json& v, const std::string& path, const std::string& what) {
    if (!v.is_number() || !std::isfinite(v.get<double>()))
        fail_in_file(path, what + " must be a finite number");
    return v.get<double>();
}

std::string string_value(const Json& v, const std::string& path, const std::string& what) {
    if (!v.is_string() || v.get<std::string>().empty())
        fail_in_file(path, what + " must be a non-empty string");
    return v.get<std::string>();
}

// The image's own value of `key`, else the defaults', else nullptr.
const Json* lookup(const Json& image, const Json& defaults, const char* key) {
    if (image.contains(key)) return &image[key];
    if (defaults.is_object() && defaults.contains(key)) return &defaults[key];
    return nullptr;
}

void read_rotation(const Json& r, SolNerfImageConfig& out, const std::string& path,
                   const std::string& where) {
    if (!r.is_object()) fail_in_file(path, where + ": rotation_deg must be an object {\"x\", \"y\", \"z\"}");
    constexpr const char* axes[] = {"x", "y", "z"};
    check_keys(r, axes, path, where + ".rotation_deg");
    for (int a = 0; a < 3; ++a)
        if (r.contains(axes[a]))
            out.rotation_deg[a] = finite_number(r[axes[a]], path, where + ".rotation_deg." + axes[a]);
}

SolNerfImageConfig read_image_entry(const Json& image, const Json& defaults, const std::string& path,
                                    std::size_t i) {
    std::string where = "images[" + std::to_string(i) + "]";
    if (!image.is_object()) fail_in_file(path, where + " must be an object");
    check_keys(image, kImageKeys, path, where);
    SolNerfImageConfig out;
    if (!image.contains("name")) fail_in_file(path, where + " has no \"name\" (the test photo)");
    out.name = string_value(image["name"], path, where + ".name");
    where += " (" + out.name + ")";
    const auto required = [&](const char* key) -> const Json& {
        const Json* v = lookup(image, defaults, key);
        if (!v) fail_in_file(path, where + " has no \"" + std::string(key) + "\" (nor does \"defaults\")");
        return *v;
    };
    out.env_map = string_value(required("env_map"), path, where + ".env_map");
    if (const Json* m = lookup(image, defaults, "mask"); m && !m->is_null())
        out.mask = string_value(*m, path, where + ".mask");
    if (const Json* r = lookup(image, defaults, "rotation_deg")) read_rotation(*r, out, path, where);
    out.hdr_threshold = finite_number(required("hdr_threshold"), path, where + ".hdr_threshold");
    out.hdr_scale = finite_number(required("hdr_scale"), path, where + ".hdr_scale");
    if (!(out.hdr_scale > 0)) fail_in_file(path, where + ".hdr_scale must be positive");
    const Json& range = required("y_range_pi");
    if (!range.is_array() || range.size() != 2)
        fail_in_file(path, where + ".y_range_pi must be [first, last] in units of pi radians");
    out.y_min = finite_number(range[0], path, where + ".y_range_pi[0]") * std::numbers::pi;
    out.y_max = finite_number(range[1], path, where + ".y_range_pi[1]") * std::numbers::pi;
    return out;
}

}  // namespace

SolNerfConfig parse_sol_nerf_config(const Json& j, const std::string& path) {
    if (!j.is_object()) fail_in_file(path, "a SOL-NeRF config must be a JSON object");
    constexpr const char* top_keys[] = {"scene", "angles", "defaults", "images"};
    check_keys(j, top_keys, path, "the config");
    SolNerfConfig config;
    config.path = path;
    if (j.contains("scene")) config.scene = string_value(j["scene"], path, "scene");
    if (j.contains("angles")) {
        if (!j["angles"].is_number_integer() || j["angles"].get<int>() < 1)
            fail_in_file(path, "angles must be a positive integer");
        config.angles = j["angles"].get<int>();
    }
    const Json defaults = j.contains("defaults") ? j["defaults"] : Json::object();
    if (!defaults.is_object()) fail_in_file(path, "defaults must be an object");
    check_keys(defaults, kImageKeys, path, "defaults");
    if (defaults.contains("name")) fail_in_file(path, "defaults cannot set \"name\"");
    if (!j.contains("images") || !j["images"].is_array() || j["images"].empty())
        fail_in_file(path, "images must be a non-empty array of test photos");
    for (std::size_t i = 0; i < j["images"].size(); ++i) {
        config.images.push_back(read_image_entry(j["images"][i], defaults, path, i));
        for (std::size_t k = 0; k + 1 < config.images.size(); ++k)
            if (config.images[k].name == config.images.back().name)
                fail_in_file(path, "image \"" + config.images.back().name + "\" is listed twice");
    }
    return config;
}

SolNerfConfig load_sol_nerf_config(const std::string& path) {
    if (!fs::exists(path)) fail_in_file(path, "missing (the SOL-NeRF config, --sol-config)");
    const Json j = Json::parse(read_text_file(path), nullptr, false);
    if (j.is_discarded()) fail_in_file(path, "not valid JSON");
    return parse_sol_nerf_config(j, path);
}

std::optional<std::string> resolve_sol_nerf_path(const std::string& configured, const std::string& root,
                                                 const std::string& scene, std::vector<std::string>& tried) {
    tried.clear();
    const fs::path p(configured);
    if (p.is_absolute())
        tried.push_back(p.string());
    else if (!root.empty())
        tried.push_back((fs::path(root) / p).string());
    else
        for (const fs::path& base : {fs::path(scene), fs::path(scene) / "final"})
            tried.push_back((base / p).string());
    std::error_code ec;
    for (const std::string& candidate : tried)
        if (fs::is_regular_file(candidate, ec)) return candidate;
    return std::nullopt;
}

std::optional<std::string> find_shipped_sol_nerf_config(const std::string& name,
                                                        const std::vector<std::string>& dirs) {
    std::error_code ec;
    for (const std::string& dir : dirs) {
        const fs::path candidate = fs::path(dir) / (name + ".json");
        if (fs::is_regular_file(candidate, ec)) return candidate.string();
    }
    return std::nullopt;
}

std::string guess_sol_nerf_scene(const std::string& scene_path) {
    std::string found;
    for (const fs::path& part : fs::path(scene_path))
        for (const char* name : {"lk2", "st", "lwp"}) {
            const std::string s = part.string(), n = name;
            if (s == n || s.rfind(n + "_", 0) == 0) found = n;  // the deepest matching component wins
        }
    return found;
}

}  // namespace lumigauss
