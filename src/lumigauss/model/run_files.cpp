#include "lumigauss/model/run_files.h"

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

void save_appearance(const std::string& path, const std::vector<std::string>& image_names) {
    nlohmann::json images = nlohmann::json::array();
    for (std::size_t i = 0; i < image_names.size(); ++i)
        images.push_back({{"name", image_names[i]}, {"index", i}});
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

void save_run_model(const RunPaths& paths, const SurfelModel& model, const LightingMlp& lighting,
                    const std::vector<std::string>& image_names, const SkyResiduals& sky_residuals) {
    save_relightable_ply(paths.model, model);
    save_lighting_mlp(paths.lighting, lighting);
    save_appearance(paths.appearance, image_names);
    if (!sky_residuals.empty()) save_sky_residuals(paths.sky, sky_residuals);
}

}  // namespace lumigauss
