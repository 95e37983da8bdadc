#pragma once
// What the viewer opens on, shared by `view` (served) and `export --format html` (one file): the lights
// (--light ones first, then the run's learned ones), the world's up, and the initial camera (--camera's
// first, else the scene's first training view, the scene being --scene or the one the run recorded).
#include <string>
#include <vector>

#include "lumigauss/model/trained_run.h"
#include "lumigauss/viewer/scene_info.h"

namespace lumigauss::cli {

struct ViewerSceneOptions {
    std::string source;       // the run folder or bare PLY `run` was loaded from
    std::string scene;        // --scene; empty: the recorded scene, if it is still there
    std::string camera_json;  // --camera; empty: none
    std::string up = "auto";  // --up
    std::vector<std::string> lights;
};

view::ViewerScene viewer_scene_for(const TrainedRun& run, const ViewerSceneOptions& options);

}  // namespace lumigauss::cli
