#include "lumigauss/model/scene_record.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/model/run_files.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

template <std::size_t N>
std::array<double, N> numbers(const Json& j, const char* key, const std::string& path) {
    if (!j.contains(key) || !j[key].is_array() || j[key].size() != N)
        fail_in_file(path,
                     std::string("every photo needs \"") + key + "\": " + std::to_string(N) + " numbers");
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
        if (!j[key][i].is_number()) fail_in_file(path, std::string("\"") + key + "\" holds a non-number");
        out[i] = j[key][i].get<double>();
    }
    return out;
}

bool has_exif(const PhotoExif& e) {
    return e.orientation != 1 || e.exposure_time_s || e.f_number || e.iso;
}

Json exif_json(const RecordedPhoto& p) {
    Json j{{"orientation", p.exif.orientation}, {"turned_upright", p.turned_upright}};
    if (p.exif.exposure_time_s) j["exposure_time_s"] = *p.exif.exposure_time_s;
    if (p.exif.f_number) j["f_number"] = *p.exif.f_number;
    if (p.exif.iso) j["iso"] = *p.exif.iso;
    if (const std::optional<double> ev = p.exif.ev100()) j["ev100"] = *ev;
    return j;
}

// The logged EXIF of a photo; what is missing or not a number stays unknown (the log is informative only).
void read_exif_json(const Json& j, RecordedPhoto& p) {
    if (!j.is_object()) return;
    const auto number = [&](const char* key) -> std::optional<double> {
        if (j.contains(key) && j[key].is_number()) return j[key].get<double>();
        return std::nullopt;
    };
    if (const auto o = number("orientation"); o && *o >= 1 && *o <= 8) p.exif.orientation = int(*o);
    if (j.contains("turned_upright") && j["turned_upright"].is_boolean())
        p.turned_upright = j["turned_upright"].get<bool>();
    p.exif.exposure_time_s = number("exposure_time_s");
    p.exif.f_number = number("f_number");
    p.exif.iso = number("iso");
}

bool close(double a, double b) {
    return std::abs(a - b) <= 1e-4 * (1.0 + std::max(std::abs(a), std::abs(b)));
}

}  // namespace

SceneRecord scene_record_of(const Dataset& scene) {
    SceneRecord r;
    std::error_code ec;
    const fs::path absolute = fs::absolute(scene.root, ec);
    r.scene = (ec ? fs::path(scene.root) : absolute).lexically_normal().string();
    r.format = scene.format;
    for (const View& v : scene.views) {
        RecordedPhoto p;
        p.name = v.name;
        p.split = split_name(v.split);
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) p.rotation[std::size_t(3 * i + j)] = v.camera.rotation(i, j);
            p.translation[std::size_t(i)] = v.camera.translation[i];
        }
        p.exif = v.exif;
        p.exif.problem.clear();
        p.turned_upright = v.image_orientation != 1;
        r.photos.push_back(std::move(p));
    }
    return r;
}

void save_scene_record(const std::string& path, const SceneRecord& record) {
    Json photos = Json::array();
    for (const RecordedPhoto& p : record.photos) {
        Json photo{
            {"name", p.name}, {"split", p.split}, {"rotation", p.rotation}, {"translation", p.translation}};
        if (has_exif(p.exif)) photo["exif"] = exif_json(p);
        photos.push_back(std::move(photo));
    }
    const Json j{{"scene", record.scene}, {"format", record.format}, {"photos", photos}};
    write_file_atomically(path, j.dump(1) + "\n");
}

std::optional<SceneRecord> load_scene_record(const std::string& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) return std::nullopt;
    const Json j = Json::parse(read_text_file(path), nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("scene") || !j["scene"].is_string() ||
        !j.contains("photos") || !j["photos"].is_array())
        fail_in_file(path, "expected a JSON object with a \"scene\" string and a \"photos\" array");
    SceneRecord r;
    r.scene = j["scene"].get<std::string>();
    if (j.contains("format") && j["format"].is_string()) r.format = j["format"].get<std::string>();
    for (const Json& e : j["photos"]) {
        if (!e.is_object() || !e.contains("name") || !e["name"].is_string())
            fail_in_file(path, "every photo needs a string \"name\"");
        RecordedPhoto p;
        p.name = e["name"].get<std::string>();
        if (e.contains("split") && e["split"].is_string()) p.split = e["split"].get<std::string>();
        p.rotation = numbers<9>(e, "rotation", path);
        p.translation = numbers<3>(e, "translation", path);
        if (e.contains("exif")) read_exif_json(e["exif"], p);
        r.photos.push_back(std::move(p));
    }
    return r;
}

void check_scene_matches(const SceneRecord& record, const std::string& record_path, const Dataset& scene) {
    std::map<std::string, const RecordedPhoto*> by_name;
    for (const RecordedPhoto& p : record.photos) by_name[p.name] = &p;
    for (const View& v : scene.views) {
        const auto it = by_name.find(v.name);
        if (it == by_name.end()) continue;
        const RecordedPhoto& p = *it->second;
        bool same = true;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                same = same && close(p.rotation[std::size_t(3 * i + j)], v.camera.rotation(i, j));
            same = same && close(p.translation[std::size_t(i)], v.camera.translation[i]);
        }
        if (!same)
            fail_in_file(scene.root, "not the scene this run was trained on: photo " + v.name +
                                         " has another camera pose than in " + record_path + " (trained on " +
                                         record.scene + ")");
    }
}

void apply_recorded_splits(const SceneRecord& record, Dataset& scene) {
    std::map<std::string, std::string> split_of;
    for (const RecordedPhoto& p : record.photos) split_of[p.name] = p.split;
    for (View& v : scene.views) {
        const auto it = split_of.find(v.name);
        if (it == split_of.end()) continue;
        for (Split s : {Split::Train, Split::Test, Split::Validation})
            if (it->second == split_name(s)) v.split = s;
    }
}

void adopt_run_scene(const std::string& run_dir, Dataset& scene) {
    const std::string record_path = run_paths(run_dir).scene;
    if (const std::optional<SceneRecord> record = load_scene_record(record_path)) {
        check_scene_matches(*record, record_path, scene);
        apply_recorded_splits(*record, scene);
    }
}

Dataset load_scene_of_run(const std::string& run_dir, const std::string& scene_dir,
                          const DatasetOptions& options) {
    Dataset scene = load_dataset(scene_dir, options);
    adopt_run_scene(run_dir, scene);
    return scene;
}

std::string scene_for_run(const std::string& run_dir, const std::string& given, const std::string& why) {
    if (!given.empty()) return given;
    const std::string record_path = run_paths(run_dir).scene;
    const std::optional<SceneRecord> record = load_scene_record(record_path);
    if (!record) throw Error(why + ": give --scene (" + run_dir + " records no scene: no scene.json)");
    std::error_code ec;
    if (!fs::is_directory(record->scene, ec))
        fail_in_file(record->scene, "the scene recorded in " + record_path +
                                        " is no longer there; give --scene (" + why + ")");
    return record->scene;
}

}  // namespace lumigauss
