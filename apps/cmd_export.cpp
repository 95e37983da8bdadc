// `lumigauss export SOURCE --format F [--light L] -o FILE`: converts a trained run (or a bare relightable
// PLY in the official LumiGauss layout) into files other tools open (docs/formats.md):
//   ply-3dgs         standard 3DGS PLY, colours baked under --light, both sides of each surfel
//                    in view-dependent SH of --sh-degree (export/ply_3dgs.h, export/two_sided_sh.h)
//   compressed-ply   PlayCanvas's compressed PLY (SuperSplat), baked like ply-3dgs, 16 bytes per splat and
//                    one byte per SH value (export/compressed_ply.h)
//   glb              binary glTF with KHR_gaussian_splatting, baked like ply-3dgs, turned so that --up is
//                    +y (export/gltf_splats.h)
//   spz              Niantic's compressed SPZ (v3), baked like ply-3dgs, turned so that --up is +y
//                    (export/spz_format.h)
//   splat            the 32-byte-per-splat web format, baked under --light, the side the training photos see
//                    (export/splat_format.h)
//   ply-relightable  the relightable PLY plus FILE.environments.json (export/relightable_bundle.h)
//   env              folder of per-photo SH text files and EXR previews (export/environment_files.h)
//   html             one self-contained web page: the relighting viewer with the model and its lights inside
//                    (viewer/standalone_page.h)
// Everything is loaded and checked before anything is written.
#include <tbb/global_control.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/compressed_ply.h"
#include "lumigauss/export/environment_files.h"
#include "lumigauss/export/export_region.h"
#include "lumigauss/export/gltf_splats.h"
#include "lumigauss/export/ply_3dgs.h"
#include "lumigauss/export/relightable_bundle.h"
#include "lumigauss/export/splat_format.h"
#include "lumigauss/export/spz_format.h"
#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/export/world_turn.h"
#include "lumigauss/io/atomic_file.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/util/error.h"
#include "lumigauss/viewer/model_payload.h"
#include "lumigauss/viewer/standalone_page.h"
#include "viewer_scene.h"

namespace lumigauss::cli {
namespace {

struct ExportOptions {
    std::string source, ply, format, out, light, up = "auto", shading = "shadowed";
    double rotate_degrees = 0, exposure = 1.0, hdr_threshold = 0.99, hdr_scale = 1.0;
    bool match_exposure = false;
    int width = 512;
    int sh_degree = 3;
    bool sh_degree_given = false;
    std::vector<std::string> bake_options_given;  // options that only shape a baked light
    std::string orient = "none";
    bool orient_given = false;
    std::optional<double> crop_radius;
    std::string crop_box;
    bool recentre = false;
    int threads = 0;
    bool quiet = false;
};

bool baked_format(const std::string& f) {
    return f == "ply-3dgs" || f == "compressed-ply" || f == "glb" || f == "spz" || f == "splat";
}

void make_parent(const std::string& path) {
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
}

// Which side a one-colour export shows (seen_side_colours).
const char* seen_side_note(const TrainedRun& run) {
    return run.photo_centres.empty() ? "the +normal side (no training cameras recorded)"
                                     : "the side the training photos see";
}

// --crop-radius, --crop-box, --recentre: the run's surfels and training cameras replaced by the region's.
void crop_and_recentre(TrainedRun& run, const ExportRegion& region, bool quiet) {
    const std::size_t before = run.model.size();
    RegionedModel kept = apply_export_region(run.model, run.photo_centres, region);
    run.model = std::move(kept.model);
    run.photo_centres = std::move(kept.cameras);
    if (quiet) return;
    if (region.radius || region.box)
        std::printf("export: the crop keeps %zu of %zu surfels\n", run.model.size(), before);
    if (region.recentre)
        std::printf(
            "export: origin moved to the region's centre %.6g,%.6g,%.6g (positions translated by "
            "%.6g,%.6g,%.6g)\n",
            kept.centre.x, kept.centre.y, kept.centre.z, kept.translation.x, kept.translation.y,
            kept.translation.z);
}

void run_export(const ExportOptions& o) {
    std::unique_ptr<tbb::global_control> threads;
    if (o.threads > 0)
        threads =
            std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, o.threads);
    if (!baked_format(o.format) && o.format != "ply-relightable" && o.format != "env" && o.format != "html")
        throw Error("--format '" + o.format +
                    "': use ply-3dgs, compressed-ply, glb, spz, splat, ply-relightable, env or html");
    if (o.source.empty() == o.ply.empty())
        throw Error("export: give either a training run folder (or relightable .ply) or --ply FILE");
    const std::string source = o.source.empty() ? o.ply : o.source;
    if (!o.ply.empty() && !is_bare_ply(o.ply)) fail_in_file(o.ply, "--ply needs an existing .ply file");
    if (o.out.empty()) throw Error("export: -o FILE is required");
    const bool baked = baked_format(o.format);
    if (baked && o.light.empty()) throw Error("--format " + o.format + " bakes colours: give --light");
    if (!baked && o.format != "html" && !o.light.empty())
        throw Error(
            "--light is for the baked formats (ply-3dgs, compressed-ply, glb, spz, splat) and html, not " +
            o.format);
    const BakeShading shading = parse_bake_shading(o.shading);
    if (o.sh_degree_given && (o.format == "splat" || !baked_format(o.format)))
        throw Error("--sh-degree is for --format ply-3dgs, compressed-ply, glb and spz (" + o.format +
                    " holds no view-dependent colour)");
    // The page relights in the browser (rotation and exposure are its sliders): nothing is baked into it.
    if (!baked && !o.bake_options_given.empty())
        throw Error(o.bake_options_given.front() +
                    " shapes a baked light (ply-3dgs, compressed-ply, glb, spz, splat); " + o.format +
                    " bakes none" +
                    (o.format == "html" ? " (the page has rotation and exposure sliders)" : ""));
    // glTF is y-up by definition, as SPZ is. SuperSplat turns every PLY it opens by 180 degrees about z (PLY
    // content has -y up, its PlayCanvas world +y: playcanvas/supersplat#451), so the compressed PLY, read by
    // little else, is y-down unless --orient says otherwise.
    const ExportOrientation orientation = o.format == "glb" ? ExportOrientation::YUp
                                          : o.format == "compressed-ply" && !o.orient_given
                                              ? ExportOrientation::YDown
                                              : parse_export_orientation(o.orient);
    if (o.orient_given && o.format != "ply-3dgs" && o.format != "compressed-ply" && o.format != "splat")
        throw Error(
            "--orient is for --format ply-3dgs, compressed-ply and splat (" + o.format +
            (o.format == "spz" || o.format == "glb" ? " is always y-up)" : " keeps the world's frame)"));
    if (o.sh_degree < 0 || o.sh_degree > 3)
        throw Error("--sh-degree " + std::to_string(o.sh_degree) + ": use 0, 1, 2 or 3");

    ExportRegion region;
    region.radius = o.crop_radius;
    if (!o.crop_box.empty()) region.box = parse_crop_box(o.crop_box, "--crop-box");
    region.recentre = o.recentre;
    if (region.any() && !baked && o.format != "ply-relightable")
        throw Error(
            "--crop-radius, --crop-box and --recentre are for the model formats (ply-3dgs, "
            "compressed-ply, glb, spz, splat, ply-relightable), not " +
            o.format);

    TrainedRun run = load_run_or_ply(source);
    if (region.any()) crop_and_recentre(run, region, o.quiet);
    // auto: the up of the training photos the run recorded; +z for a bare PLY.
    const Vec3d up = o.up == "auto" ? run.scene_up().value_or(Vec3d{0, 0, 1}) : parse_up_axis(o.up);
    if (baked) {
        PanoramaOptions popt;
        popt.frame = panorama_frame_for_up(up);
        popt.hdr_threshold = o.hdr_threshold;
        popt.hdr_scale = o.hdr_scale;
        const ResolvedLight light = resolve_light(o.light, run, popt);
        double factor = o.exposure;
        if (o.match_exposure) factor *= match_exposure_factor(light.sh, run);
        const ShCoeffs<double> env = rotate_about_up(scaled(light.sh, factor), up, o.rotate_degrees);
        const SurfelSides sides = bake_surfel_sides(run.model, env.cast<float>(), shading);
        make_parent(o.out);
        std::string how;
        // --orient: the world turned for the viewer; the colours are computed in the turned frame.
        const TurnedWorld world =
            turn_world(run.model, run.photo_centres, orientation_rotation(orientation, up));
        const std::string turn = orientation == ExportOrientation::None
                                     ? ""
                                     : "; turned so that up " + up_axis_name(up) + " is " +
                                           (orientation == ExportOrientation::YUp ? "+y" : "-y");
        if (o.format == "ply-3dgs" || o.format == "compressed-ply" || o.format == "glb") {
            const std::vector<float> view_sh =
                two_sided_view_sh(world.model, sides, o.sh_degree, world.cameras);
            if (o.format == "ply-3dgs")
                write_3dgs_ply(o.out, world.model, view_sh, o.sh_degree);
            else if (o.format == "compressed-ply")
                write_compressed_ply(o.out, world.model, view_sh, o.sh_degree);
            else
                write_gltf_splats(o.out, world.model, view_sh, o.sh_degree);
            how = (o.sh_degree > 0 ? "both sides, SH degree " + std::to_string(o.sh_degree)
                                   : std::string("one colour: ") + seen_side_note(run)) +
                  turn;
        } else if (o.format == "spz") {
            write_spz_file(o.out, run.model, sides, o.sh_degree, up, run.photo_centres);
            how = (o.sh_degree > 0 ? "both sides, SH degree " + std::to_string(o.sh_degree)
                                   : std::string("one colour: ") + seen_side_note(run)) +
                  "; turned so that up " + up_axis_name(up) + " is +y";
        } else {
            write_splat_file(
                o.out, splat_records(world.model, seen_side_colours(world.model, sides, world.cameras)));
            how = std::string("one colour: ") + seen_side_note(run) + turn;
        }
        if (!o.quiet)
            std::printf("export: %zu surfels baked (%s, %s '%s'; %s) to %s (%s)\n", run.model.size(),
                        o.shading.c_str(), light_kind_name(light.kind), light.source.c_str(), how.c_str(),
                        o.out.c_str(), o.format.c_str());
        return;
    }
    if (o.format == "html") {
        ViewerSceneOptions scene_options{source, "", "", o.up, {}};
        if (!o.light.empty()) scene_options.lights.push_back(o.light);
        const view::ViewerScene scene = viewer_scene_for(run, scene_options);
        const std::string page =
            view::standalone_viewer_page(view::encode_model_payload(run.model), view::scene_json(scene));
        make_parent(o.out);
        write_file_atomically(o.out, page);
        if (!o.quiet)
            std::printf(
                "export: %zu surfels and %zu lights in one page, %s (%.1f MB): open it in a browser\n",
                run.model.size(), scene.lights.size(), o.out.c_str(), double(page.size()) / 1e6);
        return;
    }
    if (o.format == "ply-relightable") {
        make_parent(o.out);
        const std::string sidecar = write_relightable_bundle(o.out, run, up);
        if (!o.quiet)
            std::printf("export: %zu surfels to %s, %zu environment(s) to %s\n", run.model.size(),
                        o.out.c_str(), run.image_names.size(), sidecar.c_str());
        return;
    }
    const auto files = write_environment_files(o.out, learned_environments(run), up, o.width);
    if (!o.quiet)
        std::printf("export: %zu environment(s) to %s (%zu files)\n", run.image_names.size(), o.out.c_str(),
                    files.size());
}

}  // namespace

void register_export(CLI::App& app) {
    auto o = std::make_shared<ExportOptions>();
    CLI::App* cmd = app.add_subcommand(
        "export",
        "Export a trained run (or a relightable .ply of the official LumiGauss code) as a baked 3DGS PLY, a "
        "compressed PLY (SuperSplat), a glTF (KHR_gaussian_splatting), an SPZ, a .splat, a relightable PLY "
        "with its environments, the environments alone, or one self-contained web page that relights the "
        "model in any browser (docs/formats.md)");
    cmd->add_option("source", o->source,
                    "training run folder (model.ply, lighting.lgmlp, appearance.json) or a relightable .ply");
    cmd->add_option("--ply", o->ply,
                    "a bare relightable PLY (official LumiGauss layout) instead of a run: no learned lights, "
                    "use --light with an SH .txt or a panorama");
    cmd->add_option("--format", o->format,
                    "ply-3dgs, compressed-ply, glb, spz, splat, ply-relightable, env or html")
        ->required();
    cmd->add_option(
           "-o,--output", o->out,
           "output file (ply-3dgs, compressed-ply, glb, spz, splat, html; ply-relightable: FILE.ply + "
           "FILE.environments.json) or folder (env)")
        ->required();
    cmd->add_option("--light", o->light,
                    "ply-3dgs/compressed-ply/glb/spz/splat: the lighting to bake, as for `render --light` "
                    "(training photo, SH .txt, panorama; prefixes photo:, sh:, pano:); html: one more "
                    "lighting, offered first");
    cmd->add_option("--shading", o->shading,
                    "baked colour: shadowed (the full model: transfer sets) or unshadowed (the normals)")
        ->capture_default_str();
    cmd->add_option_function<int>(
           "--sh-degree",
           [o](int degree) {
               o->sh_degree = degree;
               o->sh_degree_given = true;
           },
           "ply-3dgs, compressed-ply, glb, spz: degree of the view-dependent colour (0: one colour, the side "
           "the training photos see; 1-3: each side of a surfel shows its own colour; default 3)")
        ->type_name("INT");
    cmd->add_option_function<std::string>(
           "--orient",
           [o](const std::string& orient) {
               o->orient = orient;
               o->orient_given = true;
           },
           "ply-3dgs, compressed-ply, splat: none (the world as trained; the default but for "
           "compressed-ply), "
           "y-up (--up turned to +y, for y-up viewers and engines) or y-down (--up turned to -y: the COLMAP "
           "/ "
           "Inria 3DGS convention most splat viewers assume; compressed-ply's default, upright in "
           "SuperSplat)")
        ->type_name("TEXT");
    cmd->add_option("--crop-radius", o->crop_radius,
                    "model formats: keep the surfels within R (world units) of the region's centre (the "
                    "median surfel centre, or the --crop-box centre)");
    cmd->add_option(
        "--crop-box", o->crop_box,
        "model formats: keep the surfels inside the box X0,Y0,Z0,X1,Y1,Z1 (world axes, as trained)");
    cmd->add_flag(
        "--recentre,--recenter", o->recentre,
        "model formats: move the origin to the region's centre (engines place a model at its origin)");
    cmd->add_option("--up", o->up,
                    "world up (panorama lights, --rotate, the bundle's up): +z, -y, +y, +x, -x, -z, a vector "
                    "X,Y,Z, or auto (the run's training photos; +z for a bare PLY)")
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", o->quiet, "print nothing (errors still go to stderr)");
    cmd->add_option("--rotate", o->rotate_degrees, "turn the light by DEG about the up axis")
        ->capture_default_str();
    cmd->add_option("--exposure", o->exposure, "multiply the light SH by E")->capture_default_str();
    cmd->add_flag("--match-exposure", o->match_exposure,
                  "first scale the light to the median brightness of the run's learned lights");
    cmd->add_option("--hdr-threshold", o->hdr_threshold, "fake HDR for LDR panoramas: values above T ...")
        ->capture_default_str();
    cmd->add_option("--hdr-scale", o->hdr_scale, "... are multiplied by S")->capture_default_str();
    cmd->add_option("--preview-width,--width", o->width,
                    "env: width of the EXR previews (height = width / 2)")
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "worker threads (0: all cores)");
    cmd->callback([o, cmd] {
        ExportOptions opts = *o;
        for (const char* bake_only :
             {"--shading", "--rotate", "--exposure", "--match-exposure", "--hdr-threshold", "--hdr-scale"})
            if (cmd->count(bake_only) > 0) opts.bake_options_given.push_back(bake_only);
        run_export(opts);
    });
}

}  // namespace lumigauss::cli
