#include "viewer_scene.h"

#include <filesystem>
#include <optional>

#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/model/run_files.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/relight/light_source.h"

namespace lumigauss::cli {
namespace {

// --scene, else the scene the run recorded (RUN/scene.json) if it is still there, else none: the viewer
// works without one.
std::string scene_to_open(const ViewerSceneOptions& o) {
    if (!o.scene.empty()) return o.scene;
    const std::optional<SceneRecord> record = load_scene_record(run_paths(o.source).scene);
    std::error_code ec;
    if (!record || !std::filesystem::is_directory(record->scene, ec)) return {};
    return record->scene;
}

// The cameras "auto" estimates the up axis from, the initial one first: --camera (its first entry) wins over
// the scene (its first training view).
std::vector<Camera> known_cameras(const ViewerSceneOptions& o) {
    std::vector<Camera> cams;
    if (!o.camera_json.empty())
        for (const NamedCamera& c : read_camera_json(o.camera_json)) cams.push_back(c.camera);
    if (const std::string dir = scene_to_open(o); !dir.empty()) {
        const Dataset scene = load_scene_of_run(o.source, dir);
        const std::vector<const View*> train = scene.split(Split::Train);
        if (!train.empty()) cams.push_back(train.front()->camera);
        for (const View& v : scene.views) cams.push_back(v.camera);
    }
    return cams;
}

// --up, or for "auto" the up of the known cameras, else the run's scene_up (its training photos and the
// ground in its surfels), else +z (a bare PLY).
Vec3d resolve_up(const ViewerSceneOptions& o, const std::vector<Camera>& cams, const TrainedRun& run) {
    if (o.up != "auto") return parse_up_axis(o.up);
    if (!cams.empty()) return estimate_up_axis(cams);
    return run.scene_up().value_or(Vec3d{0, 0, 1});
}

}  // namespace

view::ViewerScene viewer_scene_for(const TrainedRun& run, const ViewerSceneOptions& o) {
    const std::vector<Camera> cams = known_cameras(o);
    const Vec3d up = resolve_up(o, cams, run);
    PanoramaOptions popt;
    popt.frame = panorama_frame_for_up(up);
    std::vector<ResolvedLight> lights;
    for (const std::string& spec : o.lights) lights.push_back(resolve_light(spec, run, popt));
    std::optional<Camera> initial;
    if (!cams.empty()) initial = cams.front();
    return view::describe_scene(run, lights, up, initial);
}

}  // namespace lumigauss::cli
