#pragma once
// The report folder of the sol-nerf protocol (eval/sol_nerf.h), in the shape of eval/report.h:
//   metrics.json       settings and every number (keys below)
//   report.md          the protocol in words, the tables, one contact sheet per test image
//   sheets/NAME.png    photo | shadowed | unshadowed | albedo | normals | shadow
//                      mask  | |shadowed - photo| x4 | |unshadowed - photo| x4 | (black: no ground truth)
//   env/NAME_sh.txt    the environment SH (world frame, at the chosen angle) each image was scored under,
//                      usable as `lumigauss render --light env/NAME_sh.txt`
// metrics.json:
//   {"protocol": "sol-nerf", "run", "scene", "config", "downscale", "angles", "mask", "environment",
//    "images": [{"name", "view", "split", "env_map", "mask_file" (null: the scene's mask), "mask_pixels",
//                "hdr": {"threshold", "scale", "boosted_values"}, "rotation_deg": {"x", "y", "z"},
//                "y_range_rad": [first, last], "best_angle_rad", "best_angle_deg", "best_index",
//                "best_at_range_edge", "search_psnr": [one per angle], "environment_sh": [[r, g, b] x 9],
//                "shadowed": {"psnr", "ssim", "mse", "mae"}, "unshadowed": {...}, "search_ms", "render_ms"}],
//    "mean": {"shadowed", "unshadowed"}, "median_render_ms", "search_seconds"}
// Non-finite numbers are written as null.
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "lumigauss/eval/report.h"
#include "lumigauss/eval/sol_nerf.h"

namespace lumigauss {

nlohmann::ordered_json sol_nerf_metrics_json(const SolNerfResult& result, const ReportSources& sources);
std::string sol_nerf_report_markdown(const SolNerfResult& result, const ReportSources& sources,
                                     bool with_sheets);

// Writes the files above into `dir` (sheets only if with_sheets and the panels were kept), each atomically.
void write_sol_nerf_report(const std::string& dir, const SolNerfResult& result, const ReportSources& sources,
                           bool with_sheets = true);

}  // namespace lumigauss
