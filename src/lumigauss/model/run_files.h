#pragma once
// The files of a training run folder:
//   config.json       the full TrainConfig (train/train_config.h), written when the run starts
//   log.jsonl         one JSON object per logged iteration with every loss term (append-only)
//   checkpoint.lgck   the latest checkpoint (train/checkpoint.h), replaced atomically
//   model.ply         the surfels, official LumiGauss relightable PLY layout (relightable_ply.h)
//   lighting.lgmlp    the lighting MLP and embedding table (lighting_mlp.h)
//   appearance.json   the photo names in embedding-table order: {"images": [{"name": ..., "index": i}]},
//                     with "exposure": k when the photo's light is k x the lighting network's output
//                     (train's exif_exposure)
//   sky.lgsky         the per-photo sky residuals (sky_residual.h), when the run trained them
//   scene.json        the scene it was trained on: path and camera poses (scene_record.h)
// Every file is written atomically (temp + rename).
#include <string>
#include <vector>

#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/model/sky_residual.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

struct RunPaths {
    std::string dir, config, log, checkpoint, model, lighting, appearance, sky, scene;
};
RunPaths run_paths(const std::string& dir);

// appearance.json for photos named in embedding order, with their exposures (none: all 1; written only for
// photos whose exposure is not 1).
void save_appearance(const std::string& path, const std::vector<std::string>& image_names,
                     const std::vector<double>& exposures = {});
// The photo names of appearance.json, in embedding order. Throws Error naming the file if malformed.
std::vector<std::string> load_appearance(const std::string& path);
// The exposures of appearance.json, in embedding order (1 where a photo has none). Throws Error naming the
// file if one is not a positive finite number.
std::vector<double> load_appearance_exposures(const std::string& path);

// model.ply, lighting.lgmlp, appearance.json and (when not empty) sky.lgsky.
void save_run_model(const RunPaths& paths, const SurfelModel& model, const LightingMlp& lighting,
                    const std::vector<std::string>& image_names, const SkyResiduals& sky_residuals,
                    const std::vector<double>& exposures = {});

}  // namespace lumigauss
