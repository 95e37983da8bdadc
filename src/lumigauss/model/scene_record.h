#pragma once
// RUN/scene.json: the scene a run was trained on, written when training starts, so that later commands on
// the run (render, eval, view) find the scene without --scene, and refuse a scene whose photos of the same
// names were taken from other cameras (another reconstruction, or another place whose photos happen to be
// named the same: that evaluated silently before).
//
//   {"scene": "/abs/path", "format": "colmap-text",
//    "photos": [{"name": "a.png", "split": "train", "rotation": [9, row-major world-to-camera],
//                "translation": [3], "exif": {...}}, ...]}
//
// Only poses are recorded, not intrinsics or image sizes: they change with -r, the poses do not. "exif" (only
// for photos with EXIF) logs what the photo's EXIF said and what was done with it: "orientation" (the tag),
// "turned_upright" (whether it was applied), "exposure_time_s", "f_number", "iso", "ev100" (those known).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/io/dataset.h"

namespace lumigauss {

struct RecordedPhoto {
    std::string name, split;
    std::array<double, 9> rotation{};
    std::array<double, 3> translation{};
    PhotoExif exif;               // what the photo's EXIF said (defaults when it had none)
    bool turned_upright = false;  // its orientation tag was applied (View::image_orientation)
};

struct SceneRecord {
    std::string scene;  // absolute path of the scene folder as it was given to train
    std::string format;
    std::vector<RecordedPhoto> photos;
};

// The record of a loaded scene (its root made absolute).
SceneRecord scene_record_of(const Dataset& scene);

// Written atomically.
void save_scene_record(const std::string& path, const SceneRecord& record);

// Nothing when the file does not exist (runs trained before it was written); Error naming the file if it
// is malformed.
std::optional<SceneRecord> load_scene_record(const std::string& path);

// Throws Error, naming both the scene and the record, if a photo of `scene` has the name of a recorded photo
// but another pose (rotation entries or translation differing by more than 1e-4 relative). Photos that only
// one side has are fine (new photos of the place, or a scene with fewer of them).
void check_scene_matches(const SceneRecord& record, const std::string& record_path, const Dataset& scene);

// Gives each photo of `scene` that the record names the split it had in training (train --test-every and
// --no-test change them): "test" then means "held out from this run", whatever the scene's split file says.
void apply_recorded_splits(const SceneRecord& record, Dataset& scene);

// For a scene loaded to work on the run folder `run_dir`: check_scene_matches and apply_recorded_splits
// against its scene.json, when it has one (a bare PLY or a run from before scene.json has none: the scene
// is taken as it is).
void adopt_run_scene(const std::string& run_dir, Dataset& scene);

// load_dataset(scene_dir, options), then adopt_run_scene(run_dir, ...).
Dataset load_scene_of_run(const std::string& run_dir, const std::string& scene_dir,
                          const DatasetOptions& options = {});

// The scene folder for a command on the run folder `run_dir`: `given` when not empty, else the one its
// scene.json records. Throws Error saying `why` the scene is needed when there is neither, or when the
// recorded folder no longer exists.
std::string scene_for_run(const std::string& run_dir, const std::string& given, const std::string& why);

}  // namespace lumigauss
