#include "lumigauss/model/trained_run.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/model/ground_albedo.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

// The world-to-camera rotations and camera centres of the training photos that scene.json records; empty
// without the record.
struct RecordedTrainingCameras {
    std::vector<Mat3d> rotations;
    std::vector<Vec3d> centres;
};
RecordedTrainingCameras recorded_training_cameras(const std::string& dir) {
    RecordedTrainingCameras cameras;
    const std::optional<SceneRecord> scene = load_scene_record(run_paths(dir).scene);
    if (!scene) return cameras;
    for (const RecordedPhoto& p : scene->photos) {
        if (p.split != "train") continue;
        Mat3d r;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) r(i, j) = p.rotation[std::size_t(3 * i + j)];
        const Vec3d t{p.translation[0], p.translation[1], p.translation[2]};
        cameras.rotations.push_back(r);
        cameras.centres.push_back(-(transpose(r) * t));
    }
    return cameras;
}

// The up of those photos (camera_up_direction); none when there are none or their rotations fix none.
std::optional<Vec3d> photos_up_of(const RecordedTrainingCameras& cameras) {
    if (cameras.rotations.empty()) return std::nullopt;
    const Vec3d up = camera_up_direction(cameras.rotations);
    if (!(length(up) > 0)) return std::nullopt;
    return up;
}

// config.json as the run wrote it. Every key is optional (a run of an older version lacks the newer ones),
// but a key that is there must have its type: anything else is a damaged or hand-edited file, named in the
// error rather than read as if the key were missing.
class RecordedConfig {
  public:
    explicit RecordedConfig(const std::string& path) : path_(path) {
        json_ = nlohmann::json::parse(read_text_file(path), nullptr, false);
        if (json_.is_discarded()) fail_in_file(path, "not valid JSON");
        if (!json_.is_object())
            fail_in_file(path, "not a JSON object (a run's config.json holds its settings)");
    }
    std::optional<double> number(const char* key) const {
        const nlohmann::json* v = find(key);
        if (v && !v->is_number()) wrong_type(key, "a number");
        return v ? std::optional<double>(v->get<double>()) : std::nullopt;
    }
    std::optional<int> integer(const char* key) const {
        const nlohmann::json* v = find(key);
        if (v && !v->is_number_integer()) wrong_type(key, "an integer");
        return v ? std::optional<int>(v->get<int>()) : std::nullopt;
    }
    std::optional<bool> flag(const char* key) const {
        const nlohmann::json* v = find(key);
        if (v && !v->is_boolean()) wrong_type(key, "true or false");
        return v ? std::optional<bool>(v->get<bool>()) : std::nullopt;
    }
    std::optional<std::string> text(const char* key) const {
        const nlohmann::json* v = find(key);
        if (v && !v->is_string()) wrong_type(key, "a string");
        return v ? std::optional<std::string>(v->get<std::string>()) : std::nullopt;
    }

  private:
    const nlohmann::json* find(const char* key) const {
        const auto it = json_.find(key);
        return it == json_.end() ? nullptr : &*it;
    }
    [[noreturn]] void wrong_type(const char* key, const char* expected) const {
        fail_in_file(path_, std::string("\"") + key + "\" must be " + expected);
    }
    std::string path_;
    nlohmann::json json_;
};

// The horizon the run was trained with (Trainer::sky_horizon): the config's angles about the up of the
// training photos. None when either is missing.
SkyHorizon recorded_sky_horizon(const RecordedConfig& config, const std::optional<Vec3d>& up) {
    SkyHorizon horizon;
    const double start = config.number("sky_horizon_start").value_or(0.0);
    const double fade = config.number("sky_horizon_fade").value_or(0.0);
    if (!(fade > 0) || !up) return horizon;
    horizon.up = up->cast<float>();
    horizon.start_degrees = float(start);
    horizon.fade_degrees = float(fade);
    return horizon;
}

// The side rule the run was trained with (Trainer::side_rule): config grazing_side_degrees about the up of
// the training photos. The official rule when either is missing.
SurfelSideRule recorded_side_rule(const RecordedConfig& config, const std::optional<Vec3d>& up) {
    SurfelSideRule rule;
    const double degrees = config.number("grazing_side_degrees").value_or(0.0);
    if (!up || !(degrees > 0 && degrees <= 45)) return rule;
    rule.up = up->cast<float>();
    rule.grazing_degrees = float(degrees);
    return rule;
}

}  // namespace

int TrainedRun::find_image(const std::string& name) const {
    for (std::size_t i = 0; i < image_names.size(); ++i)
        if (image_names[i] == name) return int(i);
    return -1;
}

ShCoeffs<double> TrainedRun::learned_sh(int index) const {
    if (index < 0 || index >= lighting.num_images())
        throw Error(paths.lighting + ": no embedding " + std::to_string(index) + " (the run has " +
                    std::to_string(lighting.num_images()) + ")");
    ShCoeffs<double> sh = lighting.env_sh(index).cast<double>();
    const double k = std::size_t(index) < exposures.size() ? exposures[std::size_t(index)] : 1.0;
    if (k != 1.0)
        for (auto& c : sh.c) c = k * c;
    return sh;
}

std::optional<Vec3d> TrainedRun::scene_up() const {
    if (!photos_up) return std::nullopt;
    return scene_up_direction(photo_rotations, photo_centres, model.centres());
}

TrainedRun load_trained_run(const std::string& dir) {
    namespace fs = std::filesystem;
    TrainedRun run;
    run.dir = dir;
    run.paths = run_paths(dir);
    if (!fs::is_directory(dir)) fail_in_file(dir, "not a folder (expected a training run folder)");
    for (const std::string* f : {&run.paths.model, &run.paths.lighting, &run.paths.appearance})
        if (!fs::exists(*f))
            fail_in_file(*f,
                         "missing: a finished training run holds model.ply, lighting.lgmlp and "
                         "appearance.json");
    run.model = load_relightable_ply(run.paths.model);
    run.lighting = load_lighting_mlp(run.paths.lighting);
    run.image_names = load_appearance(run.paths.appearance);
    run.exposures = load_appearance_exposures(run.paths.appearance);
    if (run.lighting.num_images() != int(run.image_names.size()))
        fail_in_file(run.paths.lighting, "has " + std::to_string(run.lighting.num_images()) +
                                             " embeddings but " + run.paths.appearance + " lists " +
                                             std::to_string(run.image_names.size()) + " photos");
    if (fs::exists(run.paths.sky)) {
        run.sky_residuals = load_sky_residuals(run.paths.sky);
        if (run.sky_residuals.num_images() != int(run.image_names.size()))
            fail_in_file(run.paths.sky, "has sky residuals for " +
                                            std::to_string(run.sky_residuals.num_images()) + " photos but " +
                                            run.paths.appearance + " lists " +
                                            std::to_string(run.image_names.size()));
    }
    const RecordedTrainingCameras cameras = recorded_training_cameras(dir);
    run.photos_up = photos_up_of(cameras);
    run.photo_rotations = cameras.rotations;
    run.photo_centres = cameras.centres;
    if (fs::exists(run.paths.config)) {
        const RecordedConfig c(run.paths.config);
        run.downscale = c.integer("downscale").value_or(0);
        run.sky_background = c.flag("sky_background").value_or(false);
        run.sky_pins_light = c.flag("sky_pins_light").value_or(true);
        run.lambda_sky_residual = std::max(0.0, c.number("lambda_sky_residual").value_or(0.0));
        run.lambda_sky_hemisphere = std::max(0.0, c.number("lambda_sky_hemisphere").value_or(0.0));
        run.sky_horizon = recorded_sky_horizon(c, run.photos_up);
        run.side_rule = recorded_side_rule(c, run.photos_up);
        const bool object_masks = c.text("mask_mode").value_or("") == "object";
        if (c.flag("ground_backdrop").value_or(false) && !object_masks && run.sky_horizon.fade_degrees > 0)
            run.sky_horizon.ground_albedo = ground_albedo(run.model, run.sky_horizon.up);
    }
    return run;
}

bool is_bare_ply(const std::string& path) {
    namespace fs = std::filesystem;
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".ply" && fs::is_regular_file(path);
}

RunPaths run_paths_of(const std::string& path) {
    namespace fs = std::filesystem;
    if (fs::is_directory(path)) return run_paths(path);
    const fs::path parent = fs::path(path).parent_path();
    RunPaths paths = run_paths(parent.empty() ? std::string(".") : parent.string());
    paths.model = path;
    return paths;
}

TrainedRun load_run_or_ply(const std::string& path) {
    namespace fs = std::filesystem;
    if (fs::is_directory(path)) return load_trained_run(path);
    if (!fs::exists(path))
        fail_in_file(path, "not found (expected a training run folder or a relightable .ply)");
    if (!is_bare_ply(path))
        fail_in_file(path,
                     "neither a training run folder nor a .ply file in the LumiGauss relightable layout");
    TrainedRun run;
    run.paths = run_paths_of(path);
    run.dir = run.paths.dir;
    run.paths.appearance = path + " (bare PLY: no training photos)";
    run.model = load_relightable_ply(path);
    return run;
}

}  // namespace lumigauss
