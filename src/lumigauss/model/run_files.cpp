#include "lumigauss/model/run_files.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

RunPaths run_paths(const std::string& dir) {
    const std::filesystem::path d(dir);
    return {dir,
            (d / "config.json").string(),
            (d / "log.jsonl").string(),
            (d / "checkpoint.lgck").string(),
            (d / "model.ply").string(),
            (d / "lighting.lgmlp").string(),
            (d / "appearance.json").string(),
            (d / "sky.lgsky").string(),
            (d / "scene.json").string()};
}

void save_appearance(const std::string& path, const std::vector<std::string>& image_names,
                     const std::vector<double>& exposures) {
    if (!exposures.empty() && exposures.size() != image_names.size())
        throw Error(path + ": " + std::to_string(exposures.size()) + " exposures for " +
                    std::to_string(image_names.size()) + " photos");
    nlohmann::json images = nlohmann::json::array();
    for (std::size_t i = 0; i < image_names.size(); ++i) {
        nlohmann::json image{{"name", image_names[i]}, {"index", i}};
        if (!exposures.empty() && exposures[i] != 1.0) image["exposure"] = exposures[i];
        images.push_back(std::move(image));
    }
    write_file_atomically(path, nlohmann::json{{"images", images}}.dump(2) + "\n");
}

std::vector<std::string> load_appearance(const std::string& path) {
    const nlohmann::json j = nlohmann::json::parse(read_text_file(path), nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("images") || !j["images"].is_array())
        fail_in_file(path, "expected a JSON object with an \"images\" array");
    std::vector<std::string> names(j["images"].size());
    std::vector<bool> seen(names.size(), false);
    for (const auto& e : j["images"]) {
        if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("index") ||
            !e["index"].is_number_unsigned())
            fail_in_file(path, "every image needs a string \"name\" and an unsigned \"index\"");
        const auto index = e["index"].get<std::size_t>();
        if (index >= names.size() || seen[index])
            fail_in_file(path,
                         "image indices must be 0..N-1, each once (bad index " + std::to_string(index) + ")");
        seen[index] = true;
        names[index] = e["name"].get<std::string>();
    }
    return names;
}

std::vector<double> load_appearance_exposures(const std::string& path) {
    const std::vector<std::string> names = load_appearance(path);  // checks the structure
    const nlohmann::json j = nlohmann::json::parse(read_text_file(path));
    std::vector<double> exposures(names.size(), 1.0);
    for (const auto& e : j["images"]) {
        if (!e.contains("exposure")) continue;
        if (!e["exposure"].is_number() || !(e["exposure"].get<double>() > 0) ||
            !std::isfinite(e["exposure"].get<double>()))
            fail_in_file(path, "an image's \"exposure\" must be a positive number");
        exposures[e["index"].get<std::size_t>()] = e["exposure"].get<double>();
    }
    return exposures;
}

void save_run_model(const RunPaths& paths, const SurfelModel& model, const LightingMlp& lighting,
                    const std::vector<std::string>& image_names, const SkyResiduals& sky_residuals,
                    const std::vector<double>& exposures) {
    save_relightable_ply(paths.model, model);
    save_lighting_mlp(paths.lighting, lighting);
    save_appearance(paths.appearance, image_names, exposures);
    if (!sky_residuals.empty()) save_sky_residuals(paths.sky, sky_residuals);
}

}  // namespace lumigauss
