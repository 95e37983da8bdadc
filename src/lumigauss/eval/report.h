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
// Other protocols (sol-nerf: eval/sol_nerf_report.h) write the same three kinds of files with the shared
// pieces below: the contact sheet of any per-image SheetPanels (the panels a protocol has no ground truth for
// stay black), the metrics table and JSON of ImageMetrics, and the atomic writers.
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "lumigauss/eval/gt_env.h"

namespace lumigauss {

struct ReportSources {
    std::string run, scene;
};

// ---- Shared by the protocols -----------------------------------------------------------------------------

// sheets/<image name without extension>.png (folders in the name kept), relative to the report folder.
std::string sheet_relative_path(const std::string& image_name);
// The two-row contact sheet (3 channels; empty panels are drawn black; 1-channel panels grey).
Image contact_sheet(const SheetPanels& panels);

// env/<image name without extension>_sh.txt, relative to the report folder: the light an image was scored
// under, as an SH text file (`lumigauss render --light`).
std::string sh_file_relative_path(const std::string& image_name);
// Writes each (image name, SH) pair to dir/sh_file_relative_path(name).
void write_scored_lights(const std::string& dir,
                         const std::vector<std::pair<std::string, ShCoeffs<double>>>& lights);
// [[r, g, b] x 9], coefficient order of shading/sh.h.
nlohmann::ordered_json sh_coeffs_json(const ShCoeffs<double>& sh);
// A number for metrics.json: null when not finite.
nlohmann::ordered_json json_number(double v);
// {"psnr", "ssim", "mse", "mae"}.
nlohmann::ordered_json image_metrics_json(const ImageMetrics& m);
// printf-formatted, "n/a" when not finite.
std::string format_number(const char* printf_format, double v);
// "| | PSNR | SSIM | MSE | MAE |" and one row per (label, metrics), PSNR %.2f, SSIM %.4f, MSE %.5f, MAE %.4f.
std::string metrics_table_markdown(const std::vector<std::pair<std::string, ImageMetrics>>& rows);
// The "## Contact sheets" section: `caption`, then each image's name and its sheet.
std::string contact_sheets_markdown(const std::vector<std::string>& names, const std::string& caption);

struct SheetEntry {
    std::string name;  // the image name (gives the sheet's file name)
    const SheetPanels* panels = nullptr;
};
// Writes every entry's sheet into `dir` when with_sheets and every entry has its panels (a photo); returns
// whether the sheets were written (report.md links them only then).
bool write_contact_sheets(const std::string& dir, const std::vector<SheetEntry>& entries, bool with_sheets);
// Creates `dir`, writes metrics.json (indented by 2, newline-terminated) and report.md, each atomically.
void write_report_files(const std::string& dir, const nlohmann::ordered_json& metrics,
                        const std::string& markdown);

// ---- gt-env -----------------------------------------------------------------------------------------------

nlohmann::ordered_json gt_env_metrics_json(const GtEnvResult& result, const ReportSources& sources);
std::string gt_env_report_markdown(const GtEnvResult& result, const ReportSources& sources, bool with_sheets);

// contact_sheet of the image's panels.
Image gt_env_contact_sheet(const GtEnvImageResult& image);

// Writes metrics.json, report.md and (if with_sheets and the panels were kept) sheets/*.png into `dir`,
// creating it. Every file is written atomically.
void write_gt_env_report(const std::string& dir, const GtEnvResult& result, const ReportSources& sources,
                         bool with_sheets = true);

}  // namespace lumigauss
