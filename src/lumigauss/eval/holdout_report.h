#pragma once
// The report folder of the holdout protocol (eval/holdout.h), in the shape of eval/report.h:
//   metrics.json       settings and every number (keys below)
//   report.md          the protocol in words, the tables, one contact sheet per test image
//   sheets/NAME.png    photo | shadowed | unshadowed | albedo | normals | shadow
//                      score mask | |shadowed - photo| x4 | |unshadowed - photo| x4 | (black: no ground
//                      truth)
//   env/NAME_sh.txt, env/NAME_unshadowed_sh.txt
//                      the lights fitted on the left half of each photo (`lumigauss render --light`)
// metrics.json:
//   {"protocol": "holdout", "run", "scene", "downscale", "views", "fit": {"variable", "iterations",
//    "renders", "fit_mask", "score_mask"},
//    "images": [{"name", "fit_pixels", "score_pixels", "fit_psnr": {"shadowed", "unshadowed"}, "fit_ms",
//                "render_ms", "environment_sh": {"shadowed": [[r, g, b] x 9], "unshadowed": [...]},
//                "shadowed": {"psnr", "ssim", "mse", "mae"},
//                "unshadowed": {...}}],
//    "mean": {"shadowed", "unshadowed", "fit_psnr": {"shadowed", "unshadowed"}}, "median_fit_ms",
//    "median_render_ms"}
// Non-finite numbers are written as null.
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "lumigauss/eval/holdout.h"
#include "lumigauss/eval/report.h"

namespace lumigauss {

nlohmann::ordered_json holdout_metrics_json(const HoldoutResult& result, const ReportSources& sources,
                                            int downscale);
std::string holdout_report_markdown(const HoldoutResult& result, const ReportSources& sources, int downscale,
                                    bool with_sheets);

// Writes the files above into `dir` (sheets only if with_sheets and the panels were kept), each atomically.
void write_holdout_report(const std::string& dir, const HoldoutResult& result, const ReportSources& sources,
                          int downscale, bool with_sheets = true);

}  // namespace lumigauss
