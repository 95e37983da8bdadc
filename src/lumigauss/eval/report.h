#pragma once
// The files of an evaluation report folder:
//   metrics.json     every number: the protocol's settings (light scale and its fit, albedo scales), per
//                    image metrics and their means (keys below)
//   report.md        the same as tables, the protocol in words, and one contact sheet per test image
//   sheets/NAME.png  contact sheet, two rows of six panels:
//                      photo | shadowed | unshadowed | albedo | normals | shadow
//                      mask  | |shadowed - photo| x4 | |unshadowed - photo| x4 | gt albedo | gt normals |
//                      normal error (angle / 45 deg)
// metrics.json (gt-env):
//   {"protocol": "gt-env", "run", "scene", "downscale",
//    "light_scale": {"value", "method", "train_photos", "relative_residual", "per_photo": {name: k_i}},
//    "test_exposure", "mask",
//    "albedo_scale": {"linear": [r, g, b], "gamma": [r, g, b]}       (only with gt/albedo)
//    "images": [{"name", "condition", "exposure", "mask_pixels",
//                "shadowed": {"psnr", "ssim", "mse", "mae"}, "unshadowed": {...},
//                "albedo": {"psnr", "mse", "mae"}, "albedo_gamma": {...},                 (with gt/albedo)
//                "normal": {"mean_deg", "median_deg", "pixels", "missing"}}],             (with gt/normal)
//    "mean": {"shadowed", "unshadowed", "albedo", "albedo_gamma", "normal"},
//    "normal_all_pixels": {"mean_deg", "median_deg", "pixels", "missing"}}
// Non-finite numbers are written as null.
#include <nlohmann/json.hpp>
#include <string>

#include "lumigauss/eval/gt_env.h"

namespace lumigauss {

struct ReportSources {
    std::string run, scene;
};

nlohmann::ordered_json gt_env_metrics_json(const GtEnvResult& result, const ReportSources& sources);
std::string gt_env_report_markdown(const GtEnvResult& result, const ReportSources& sources, bool with_sheets);

// The two-row contact sheet of one image (3 channels; empty panels are drawn black; 1-channel panels grey).
Image gt_env_contact_sheet(const GtEnvImageResult& image);

// Writes metrics.json, report.md and (if with_sheets and the panels were kept) sheets/*.png into `dir`,
// creating it. Every file is written atomically.
void write_gt_env_report(const std::string& dir, const GtEnvResult& result, const ReportSources& sources,
                         bool with_sheets = true);

}  // namespace lumigauss
