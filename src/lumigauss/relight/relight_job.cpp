#include "lumigauss/relight/relight_job.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <optional>

#include "lumigauss/cameras/orbit.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/model/scene_record.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/relight/relit_sky.h"
#include "lumigauss/relight/video.h"
#include "lumigauss/shading/sh4_rotation.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/text.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;

bool is_split_keyword(const std::string& s) {
    return s == "train" || s == "test" || s == "validation" || s == "all";
}

// Keeps the cameras whose name (or original image name) is listed; every listed name must match.
std::vector<NamedCamera> filter_views(std::vector<NamedCamera> cameras,
                                      const std::vector<std::string>& image_names,
                                      const std::vector<std::string>& wanted, const std::string& source) {
    if (wanted.empty()) return cameras;
    std::vector<NamedCamera> kept;
    for (const std::string& w : wanted) {
        bool found = false;
        for (std::size_t i = 0; i < cameras.size(); ++i)
            if (cameras[i].name == w || (i < image_names.size() && image_names[i] == w)) {
                kept.push_back(cameras[i]);
                found = true;
                break;
            }
        if (!found) {
            std::string some;
            for (std::size_t i = 0; i < cameras.size() && i < 5; ++i)
                some += (i ? ", " : "") + cameras[i].name;
            if (cameras.size() > 5) some += ", ...";
            throw Error("--view '" + w + "': no such camera among the " + std::to_string(cameras.size()) +
                        " of " + source + " (" + some + ")");
        }
    }
    return kept;
}

Vec3d model_centre(const SurfelModel& model) {
    const auto& xyz = model.param(ModelParam::Xyz);
    std::vector<Vec3f> points(model.size());
    for (std::size_t i = 0; i < points.size(); ++i) points[i] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    return point_cloud_centre(points);
}

// The scene's SfM points, where the ground that refines the photos' up is found (cameras/up_axis.h).
std::vector<Vec3d> sfm_points(const Dataset& scene) {
    std::vector<Vec3d> points;
    for (const Vec3f& p : scene.point_xyz) points.push_back({p.x, p.y, p.z});
    return points;
}

std::string fmt(const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

}  // namespace

RelightCameras relight_cameras(const RelightJob& job, const TrainedRun& run) {
    RelightCameras rc;
    const bool from_json = job.cameras != "orbit" && !is_split_keyword(job.cameras);
    if (from_json) {
        if (!fs::is_regular_file(job.cameras))
            fail_in_file(
                job.cameras,
                "--cameras: not train, test, validation, all or orbit, and not an existing camera JSON "
                "file");
        rc.cameras = read_camera_json(job.cameras);
        if (job.downscale > 1)
            for (NamedCamera& c : rc.cameras)
                c.camera = c.camera.resized(downscaled_size(c.camera.width, job.downscale),
                                            downscaled_size(c.camera.height, job.downscale));
        std::vector<Camera> plain;
        for (const NamedCamera& c : rc.cameras) plain.push_back(c.camera);
        // A camera file is a path someone designed (an orbit, a fly-through): its own up, without the ground.
        rc.up = job.up == "auto" ? estimate_up_axis(plain) : parse_up_axis(job.up);
        rc.cameras = filter_views(std::move(rc.cameras), {}, job.views, job.cameras);
        return rc;
    }
    const std::string scene_dir =
        scene_for_run(job.run, job.scene, "--cameras " + job.cameras + " needs the scene's cameras");
    DatasetOptions dopt;
    dopt.downscale = job.downscale > 0 ? job.downscale : (run.downscale > 0 ? run.downscale : 1);
    const Dataset scene = load_scene_of_run(job.run, scene_dir, dopt);
    if (scene.views.empty()) throw Error(scene_dir + ": the scene has no view");
    std::vector<Camera> all;
    for (const View& v : scene.views) all.push_back(v.camera);
    rc.up = job.up == "auto" ? estimate_up_axis(all, sfm_points(scene)) : parse_up_axis(job.up);
    if (job.cameras == "orbit") {
        rc.orbit = true;
        if (job.orbit_frames < 1) throw Error("--frames must be at least 1");
        const Vec3d centre =
            scene.point_xyz.empty() ? model_centre(run.model) : point_cloud_centre(scene.point_xyz);
        const Orbit orbit = orbit_from_cameras(all, centre, rc.up);
        rc.cameras = orbit_cameras(orbit, scene.views.front().camera, job.orbit_frames);
        rc.cameras = filter_views(std::move(rc.cameras), {}, job.views, "the orbit");
        return rc;
    }
    std::vector<std::string> image_names;
    for (const View& v : scene.views) {
        if (job.cameras != "all" && job.cameras != split_name(v.split)) continue;
        rc.cameras.push_back({without_extension(v.name), v.camera});
        image_names.push_back(v.name);
    }
    if (rc.cameras.empty())
        throw Error(scene_dir + ": no view is in split '" + job.cameras +
                    "' (--cameras all renders every view)");
    rc.cameras = filter_views(std::move(rc.cameras), image_names, job.views,
                              scene_dir + " (split " + job.cameras + ")");
    return rc;
}

namespace {

// The sky residual a light brings (a training photo's, an SH file's; resolve_light), turned about `up` with
// the light (the whole sky turns, as rotate_about_up turns the light).
std::optional<Sh4Coeffs<float>> light_sky_residual(const ResolvedLight& light, Vec3d up, double degrees) {
    std::optional<Sh4Coeffs<float>> residual = light.sky_residual;
    if (residual && degrees != 0)
        residual = rotate_sh4(*residual, rotation_about_axis(up, degrees * std::numbers::pi / 180.0));
    return residual;
}

// The sky of one frame: the panorama itself for a panorama light, else the SH plus its residual, if any.
Image frame_sky(const Camera& camera, const RelightSummary& summary, const TrainedRun& run,
                const ShCoeffs<float>& env, const Mat3d& frame, double degrees) {
    const ResolvedLight& light = summary.light;
    if (light.kind == LightKind::Panorama && !light.panorama.pixels.empty())
        return panorama_sky_image(
            camera, {&light.panorama, frame, Vec3d{1, 1, 1} * summary.light_factor, summary.up, degrees, {}});
    // The horizon is about the frame the model was trained in, so a turned light keeps it.
    std::optional<Sh4Coeffs<float>> residual = light_sky_residual(light, summary.up, degrees);
    if (!residual) return sky_image(camera, env, nullptr, run.sky_horizon);
    for (Vec3f& c : residual->c) c = float(summary.light_factor) * c;
    return sky_image(camera, env, &*residual, run.sky_horizon);
}

}  // namespace

RelightSummary run_relight_job(const RelightJob& job, const std::function<void(const std::string&)>& log) {
    auto say = [&](const std::string& line) {
        if (log) log(line);
    };
    if (job.light.empty()) throw Error("--light is required to render a run");
    if (job.spin < 0) throw Error("--spin must be positive");
    if (job.fps < 1) throw Error("--fps must be positive");
    if (!(job.exposure > 0) || !std::isfinite(job.exposure))
        throw Error("--exposure must be a positive number");
    if (!(job.hdr_scale > 0) || !std::isfinite(job.hdr_scale)) throw Error("--hdr-scale must be positive");
    if (job.spin > 0 && job.cameras == "orbit")
        throw Error("--spin and --cameras orbit both animate; choose one");

    // Everything is loaded and checked before the output folder is made.
    const TrainedRun run = load_run_or_ply(job.run);
    RelightCameras cams = relight_cameras(job, run);
    RelightSummary summary;
    summary.up = cams.up;
    summary.cameras = cams.cameras;
    PanoramaOptions popt;
    popt.frame = panorama_frame_for_up(cams.up);
    popt.hdr_threshold = job.hdr_threshold;
    popt.hdr_scale = job.hdr_scale;
    summary.light = resolve_light(job.light, run, popt);
    summary.light_factor = job.exposure;
    if (job.match_exposure) summary.light_factor *= match_exposure_factor(summary.light.sh, run);
    const ShCoeffs<double> base =
        summary.light_factor == 1.0 ? summary.light.sh : scaled(summary.light.sh, summary.light_factor);

    say("render: " + std::to_string(run.model.size()) + " surfels from " + job.run +
        "; light: " + light_kind_name(summary.light.kind) + " " + summary.light.source +
        (summary.light.boosted ? " (fake HDR boost)" : "") +
        (summary.light.sky_residual && job.outputs.sky_background ? " (its sky with the photo's residual)"
                                                                  : "") +
        ", scale " + fmt("%.6g", summary.light_factor) + ", up " + up_axis_name(cams.up) + "; " +
        std::to_string(cams.cameras.size()) + " camera(s)");
    if (summary.light.kind == LightKind::Panorama && job.hdr_scale != 1.0 &&
        !is_ldr_panorama(summary.light.source))
        say("  note: --hdr-scale applies to LDR panoramas (PNG/JPEG) only; " + summary.light.source +
            " is used as is");

    fs::create_directories(job.out);
    if (cams.orbit) write_camera_json((fs::path(job.out) / "orbit_cameras.json").string(), cams.cameras);

    const std::vector<double> angles =
        job.spin > 0 ? spin_angles(job.spin, job.rotate_degrees) : std::vector<double>{job.rotate_degrees};
    RelitRenderer renderer(run.model, job.backend, run.side_rule);
    for (const NamedCamera& nc : cams.cameras) {
        for (std::size_t k = 0; k < angles.size(); ++k) {
            const auto t0 = std::chrono::steady_clock::now();
            const std::string stem = job.spin > 0 ? frame_name(nc.name + "_spin", int(k), job.spin) : nc.name;
            const ShCoeffs<float> env = rotate_about_up(base, cams.up, angles[k]).cast<float>();
            const RasterImages<float>& raster = renderer.render(nc.camera, env);
            Image sky;
            if (job.outputs.sky_background)
                sky = frame_sky(nc.camera, summary, run, env, popt.frame, angles[k]);
            const std::vector<std::string> files = write_relit_frame(
                job.out, stem, raster, job.outputs, job.outputs.sky_background ? &sky : nullptr);
            ++summary.frames;
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            say("  [" + std::to_string(summary.frames) + "] " + relit_path(job.out, stem, "") + "  " +
                std::to_string(nc.camera.width) + "x" + std::to_string(nc.camera.height) +
                (job.spin > 0 ? "  rotation " + fmt("%.1f", angles[k]) + " deg" : "") + "  " +
                std::to_string(files.size()) + " files  " + fmt("%.1f", ms) + " ms");
        }
    }

    // Videos of the animated sequences.
    const bool animated = (job.spin >= 2) || (cams.orbit && cams.cameras.size() >= 2 && job.views.empty());
    if (animated && job.video) {
        if (!job.outputs.shadowed) {
            summary.video_note = "no video: the shadowed frames are not written (--outputs)";
        } else {
            const std::string ffmpeg = find_on_path("ffmpeg");
            if (ffmpeg.empty()) {
                summary.video_note = "no video: ffmpeg is not on the PATH (the PNG frames are written)";
            } else {
                std::vector<std::pair<std::string, std::string>> jobs;  // pattern, output
                if (cams.orbit) {
                    const std::string digits =
                        std::to_string(frame_name("", 0, int(cams.cameras.size())).size());
                    jobs.push_back(
                        {escape_percent(relit_path(job.out, "orbit_", "")) + "%0" + digits + "d_shadowed.png",
                         relit_path(job.out, "orbit", "_shadowed.mp4")});
                } else {
                    const std::string digits = std::to_string(frame_name("", 0, job.spin).size());
                    for (const NamedCamera& nc : cams.cameras)
                        jobs.push_back({escape_percent(relit_path(job.out, nc.name + "_spin", "")) + "%0" +
                                            digits + "d_shadowed.png",
                                        relit_path(job.out, nc.name, "_shadowed.mp4")});
                }
                for (const auto& [pattern, output] : jobs) {
                    if (encode_video(ffmpeg, pattern, output, job.fps))
                        summary.videos.push_back(output);
                    else
                        summary.video_note = "ffmpeg failed on " + pattern;
                }
            }
        }
        if (!summary.video_note.empty()) say("  " + summary.video_note);
        for (const std::string& v : summary.videos) say("  video " + v);
    }
    return summary;
}

}  // namespace lumigauss
