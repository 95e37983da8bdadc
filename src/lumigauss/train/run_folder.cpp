#include "lumigauss/train/run_folder.h"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/scene/relightable_ply.h"
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
            (d / "sky.lgsky").string()};
}

void save_run_model(const RunPaths& paths, const TrainState& state) {
    save_relightable_ply(paths.model, state.model);
    save_lighting_mlp(paths.lighting, state.lighting);
    nlohmann::json images = nlohmann::json::array();
    for (std::size_t i = 0; i < state.image_names.size(); ++i)
        images.push_back({{"name", state.image_names[i]}, {"index", i}});
    write_file_atomically(paths.appearance, nlohmann::json{{"images", images}}.dump(2) + "\n");
    if (!state.sky_residuals.empty()) save_sky_residuals(paths.sky, state.sky_residuals);
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

std::string step_log_line(const StepReport& r, double elapsed_seconds) {
    nlohmann::json j;
    j["iteration"] = r.iteration;
    j["stage"] = int(r.stage);
    j["view"] = r.view;
    j["total"] = r.total;
    j["l1_shadowed"] = r.l1_shadowed;
    j["dssim_shadowed"] = r.dssim_shadowed;
    j["l1_unshadowed"] = r.l1_unshadowed;
    j["dssim_unshadowed"] = r.dssim_unshadowed;
    j["range01"] = r.range01;
    j["consistency"] = r.consistency;
    j["shadow"] = r.shadow;
    j["env"] = r.env;
    j["normal"] = r.normal;
    j["distortion"] = r.distortion;
    j["sky_alpha"] = r.sky_alpha;
    j["sky_colour"] = r.sky_colour;
    j["background_alpha"] = r.background_alpha;
    j["opacity"] = r.opacity;
    j["sky_residual"] = r.sky_residual;
    j["psnr"] = r.psnr;
    j["surfels"] = r.surfels;
    if (r.densify_ran) {
        j["cloned"] = r.densified.cloned;
        j["split"] = r.densified.split;
        j["pruned"] = r.densified.pruned;
    } else if (r.prune_ran) {
        j["pruned"] = r.densified.pruned;
    }
    if (r.opacity_reset) j["opacity_reset"] = true;
    j["elapsed_s"] = elapsed_seconds;
    return j.dump();
}

}  // namespace lumigauss
