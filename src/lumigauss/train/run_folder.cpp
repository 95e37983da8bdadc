#include "lumigauss/train/run_folder.h"

#include <filesystem>
#include <nlohmann/json.hpp>

namespace lumigauss {

void save_run_model(const RunPaths& paths, const TrainState& state, const std::vector<float>& exposures) {
    save_run_model(paths, state.model, state.lighting, state.image_names, state.sky_residuals,
                   std::vector<double>(exposures.begin(), exposures.end()));
}

std::string step_log_line(const StepReport& r, double elapsed_seconds, const HeldOutLog& held_out) {
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
    j["ground_light"] = r.ground_light;
    j["normal"] = r.normal;
    j["distortion"] = r.distortion;
    j["sky_alpha"] = r.sky_alpha;
    j["sky_colour"] = r.sky_colour;
    j["background_alpha"] = r.background_alpha;
    j["opacity"] = r.opacity;
    j["sky_residual"] = r.sky_residual;
    j["sky_hemisphere"] = r.sky_hemisphere;
    j["scale_ratio"] = r.scale_ratio;
    // The transfer-fitting stage renders no photo: null, not 0, so that plots of the log show a gap, not a
    // dip.
    if (r.stage == Stage::TransferFitting)
        j["psnr"] = nullptr;
    else
        j["psnr"] = r.psnr;
    j["surfels"] = r.surfels;
    if (r.densify_ran) {
        j["cloned"] = r.densified.cloned;
        j["split"] = r.densified.split;
        j["pruned"] = r.densified.pruned;
    } else if (r.prune_ran) {
        j["pruned"] = r.densified.pruned;
    }
    if (r.empty_space_swept) {
        j["empty_space_pruned"] = r.empty_space_pruned;
        j["low_contribution_pruned"] = r.low_contribution_pruned;
        j["weakly_seen_ground_pruned"] = r.weakly_seen_ground_pruned;
    }
    if (r.opacity_reset) j["opacity_reset"] = true;
    if (held_out.score) {
        j["held_out_psnr"] = held_out.score->psnr;
        j["held_out_photos"] = held_out.score->photos;
        j["held_out_s"] = held_out.seconds;
    }
    if (!held_out.error.empty()) j["held_out_error"] = held_out.error;
    j["elapsed_s"] = elapsed_seconds;
    return j.dump();
}

}  // namespace lumigauss
