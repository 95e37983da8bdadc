#pragma once
// `lumigauss render RUN --light L ...`: renders a trained run from a set of cameras under one environment
// (optionally turning), writing relit_outputs.h's files per frame and, with ffmpeg on the PATH, MP4s.
//
// Order of work: the run, the light and the cameras are all loaded and checked before anything is written,
// so a bad argument leaves no output folder behind. Then, per camera, per frame:
//   env = rotate_about_up(exposure * light SH, up, rotate + k * 360 / spin)        (up_axis.h)
//   RelitRenderer::render(camera, env) -> write_relit_frame(...)
// Frame names: the view's image name without extension; with --spin N, STEM_spinKKK; for an orbit,
// orbit_KKK (its cameras are also written to OUT/orbit_cameras.json, readable back with --cameras).
// Videos (shadowed frames, `fps`): STEM_shadowed.mp4 per camera for a spin, orbit_shadowed.mp4 for an orbit.
#include <functional>
#include <string>
#include <vector>

#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/relight/relit_outputs.h"
#include "lumigauss/render/rasterizer.h"

namespace lumigauss {

struct RelightJob {
    std::string run;    // training run folder
    std::string scene;  // scene folder: needed for train/test/validation/all/orbit cameras
    std::string out = "relit";
    std::string cameras = "test";    // train, test, validation, all, orbit, or a camera JSON file
    std::vector<std::string> views;  // keep only these cameras (image name, its stem, or JSON name)
    int downscale = 0;               // 0: the run's training resolution for scene cameras, 1 for JSON
    std::string light;               // see light_source.h
    std::string up = "auto";         // up_axis.h, or "auto" (the cameras' up)
    double rotate_degrees = 0;
    int spin = 0;           // > 0: that many frames turning the environment through 360 deg
    int orbit_frames = 60;  // cameras of --cameras orbit
    double exposure = 1.0;  // multiplies the light SH
    bool match_exposure = false;
    double hdr_threshold = 0.99, hdr_scale = 1.0;
    RelitOutputs outputs;
    bool video = true;
    int fps = 15;
    RasterBackend backend = RasterBackend::Cpu;
};

struct RelightSummary {
    ResolvedLight light;
    double light_factor = 1.0;  // exposure (times the --match-exposure factor)
    Vec3d up{0, 0, 1};
    std::vector<NamedCamera> cameras;
    int frames = 0;
    std::vector<std::string> videos;
    std::string video_note;  // why no video was made, when one could have been
};

struct RelightCameras {
    std::vector<NamedCamera> cameras;
    Vec3d up{0, 0, 1};  // job.up parsed, or estimated from the scene's (or the JSON's) cameras for "auto"
    bool orbit = false;
};

// The cameras the job renders (scene views, orbit or JSON), filtered by `views`, and the up axis. Throws
// Error naming the scene, file or view. Writes nothing.
RelightCameras relight_cameras(const RelightJob& job, const TrainedRun& run);

// Runs the job; `log` receives one line per frame and a few facts (pass {} for silence). Throws Error on bad
// input (before anything is written, see above).
RelightSummary run_relight_job(const RelightJob& job, const std::function<void(const std::string&)>& log);

}  // namespace lumigauss
