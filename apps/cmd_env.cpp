// `lumigauss env`: equirectangular panorama <-> degree-2 environment SH, in the world frame the other
// commands use (`render --light`, `export`):
//   lumigauss env PANORAMA -o sh.txt [--up AXIS] [--rotate DEG] [--hdr-threshold T --hdr-scale S]
//                 [--preview out.exr|out.png] [--preview-width W] [--irradiance]
//   lumigauss env --sh sh.txt --preview out.exr|out.png [--up AXIS] [--rotate DEG] [--preview-width W] [--irradiance]
// The projection is relight/light_source.h's panorama_light (shading/envmap.h: exact pixel solid angles), the
// preview shading/envmap.h's render_sh_panorama, so a preview read back gives the same SH up to quadrature.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>

#include "commands.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/image.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"

namespace lumigauss::cli {
namespace {

namespace fs = std::filesystem;

struct EnvOptions {
    std::string panorama, sh, out, preview, up = "+z";
    double rotate_degrees = 0, hdr_threshold = 0.99, hdr_scale = 1.0;
    int width = 512;
    bool irradiance = false, quiet = false;
};

std::string lower_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

void check_options(const EnvOptions& o) {
    if (o.panorama.empty() == o.sh.empty())
        throw Error("env: give either a PANORAMA to project or --sh FILE to preview, not both");
    if (!o.panorama.empty() && o.out.empty() && o.preview.empty())
        throw Error("env: nothing to write: give -o sh.txt and/or --preview FILE");
    if (!o.sh.empty() && o.preview.empty()) throw Error("env --sh: give --preview out.exr|out.png");
    if (!o.preview.empty() && lower_extension(o.preview) != ".exr" && lower_extension(o.preview) != ".png")
        fail_in_file(o.preview, "--preview must end in .exr (float radiance) or .png (clamped to [0, 1])");
    if (!(o.hdr_scale > 0) || !std::isfinite(o.hdr_scale) || !std::isfinite(o.hdr_threshold))
        throw Error("env: --hdr-scale must be positive and --hdr-threshold finite");
    if (o.width < 2 || o.width % 2 != 0) throw Error("env: --preview-width must be an even number >= 2");
}

// The environment the options name, in the world frame and turned by --rotate.
ShCoeffs<double> load_environment(const EnvOptions& o, const Mat3d& frame, Vec3d up) {
    ShCoeffs<double> sh;
    if (!o.sh.empty()) {
        sh = read_sh_text(o.sh);
    } else {
        if (!fs::exists(o.panorama)) fail_in_file(o.panorama, "missing (the panorama to project)");
        if (!is_panorama_file(o.panorama))
            fail_in_file(o.panorama, "not a panorama: use an equirectangular .hdr, .exr, .png or .jpg");
        PanoramaOptions popt;
        popt.frame = frame;
        popt.hdr_threshold = o.hdr_threshold;
        popt.hdr_scale = o.hdr_scale;
        bool boosted = false;
        sh = panorama_light(o.panorama, popt, &boosted);
        if (!o.quiet && o.hdr_scale != 1.0)
            std::printf("env: fake HDR %s (values > %g times %g)\n",
                        !is_ldr_panorama(o.panorama) ? "not applied: HDR/EXR panoramas are radiance already"
                        : boosted                    ? "applied"
                                                     : "changed no pixel",
                        o.hdr_threshold, o.hdr_scale);
    }
    return rotate_about_up(sh, up, o.rotate_degrees);
}

void write_preview(const EnvOptions& o, const ShCoeffs<double>& sh, const Mat3d& frame) {
    const int w = o.width, h = o.width / 2;
    Image pano =
        o.irradiance ? render_irradiance_panorama(sh, w, h, frame) : render_sh_panorama(sh, w, h, frame);
    if (o.irradiance)
        for (float& v : pano.pixels) v = float(double(v) / std::numbers::pi);
    if (lower_extension(o.preview) == ".exr")
        write_exr(o.preview, pano);
    else
        write_png(o.preview, pano);
}

void run_env(const EnvOptions& o) {
    check_options(o);
    const Vec3d up = parse_up_axis(o.up);
    const Mat3d frame = panorama_frame_for_up(up);
    const ShCoeffs<double> sh = load_environment(o, frame, up);
    if (!o.out.empty()) write_sh_text(o.out, sh);
    if (!o.preview.empty()) write_preview(o, sh, frame);
    if (o.quiet) return;
    std::printf("env: %s -> DC (L00) %.6g %.6g %.6g, up %s\n",
                o.sh.empty() ? o.panorama.c_str() : o.sh.c_str(), sh.c[0].x, sh.c[0].y, sh.c[0].z,
                up_axis_name(up).c_str());
    if (!o.out.empty()) std::printf("env: wrote %s\n", o.out.c_str());
    if (!o.preview.empty())
        std::printf("env: wrote %s (%d x %d, %s)\n", o.preview.c_str(), o.width, o.width / 2,
                    o.irradiance ? "irradiance / pi" : "radiance");
}

// Where the centre column and the column a quarter width left of it look, for an up axis (from the frame
// itself, so the text cannot drift from the code).
std::string axis_row(const char* up_text) {
    const Mat3d frame = panorama_frame_for_up(parse_up_axis(up_text));
    auto name = [](Vec3d v) { return up_axis_name(v); };
    return std::string("  --up ") + up_text + ": row 0 looks along " + name(frame * Vec3d{0, 0, 1}) +
           ", the centre column along " + name(frame * Vec3d{1, 0, 0}) +
           ", a quarter width left of it along " + name(frame * Vec3d{0, 1, 0}) + "\n";
}

std::string convention_text() {
    std::string s =
        "Convention. A W x H equirectangular panorama (any size; 2:1 usual), pixel (row i, column j) is the "
        "direction at polar angle theta = pi (i + 0.5) / H from the up axis (row 0 = straight up, the last "
        "row straight down) and azimuth phi = 2 pi (0.5 - (j + 0.5) / W) about it: the centre column looks "
        "along the frame's +X, azimuth DEcreases to the right (a panorama photo seen from inside; Blender's "
        "Environment Texture), the left and right edges meet behind. World directions per --up:\n";
    for (const char* up : {"+z", "-y", "+y", "-z", "+x", "-x"}) s += axis_row(up);
    s +=
        "--rotate DEG then turns the environment about the up axis, counter-clockwise seen from above.\n"
        "SH. Real spherical harmonics of degree 2 without the Condon-Shortley phase, 9 coefficients in the "
        "order (l,m) = (0,0) (1,-1) (1,0) (1,1) (2,-2) (2,-1) (2,0) (2,1) (2,2): 0.282095; 0.488603 y, z, x; "
        "1.092548 xy, yz; 0.315392 (3z^2 - 1); 1.092548 xz; 0.546274 (x^2 - y^2), x y z the world direction. "
        "The text file has 9 lines \"R G B\": RADIANCE coefficients L_lm = sum over pixels of L Y_lm dOmega "
        "(exact pixel solid angles), in the panorama's units, in the world frame (the format of `render "
        "--light` and the official --envmaps files).\n"
        "Values. HDR/EXR pixels are radiance as stored. PNG/JPEG are used as stored, value/255, with NO sRGB "
        "linearisation (as the official evaluation); --hdr-scale S multiplies every channel value above "
        "--hdr-threshold T by S (its fake HDR for the clipped sun; LDR files only).\n"
        "Preview. The SH radiance (or with --irradiance the irradiance / pi, the official diffuse map) at "
        "every pixel direction of a W x W/2 panorama in the same convention: EXR float, PNG clamped to [0, "
        "1] "
        "with no gamma (so PNG -> SH -> PNG keeps the /255 convention).";
    return s;
}

}  // namespace

void register_env(CLI::App& app) {
    auto o = std::make_shared<EnvOptions>();
    CLI::App* cmd = app.add_subcommand(
        "env", "Project an equirectangular panorama onto degree-2 SH (world frame), or preview an SH file");
    cmd->add_option("panorama", o->panorama, "equirectangular panorama: .hdr, .exr, .png, .jpg");
    cmd->add_option("--sh", o->sh, "SH text file (9 lines R G B) to preview instead");
    cmd->add_option("-o,--output", o->out, "SH text file to write (9 lines R G B, radiance, world frame)");
    cmd->add_option("--preview", o->preview, "write the SH as a panorama: .exr (float) or .png (clamped)");
    cmd->add_option("--preview-width,--width", o->width, "preview width in pixels (height = width / 2)")
        ->capture_default_str();
    cmd->add_flag("--irradiance", o->irradiance, "preview the irradiance / pi instead of the radiance");
    cmd->add_option("--up", o->up,
                    "world up axis: +z (synthetic scenes, Blender), -y (COLMAP/NeRF-OSR), +y, ...")
        ->capture_default_str();
    cmd->add_option("--rotate", o->rotate_degrees, "turn the environment by DEG about the up axis")
        ->capture_default_str();
    cmd->add_option("--hdr-threshold", o->hdr_threshold,
                    "fake HDR for LDR panoramas: values above T (of 1) ...")
        ->capture_default_str();
    cmd->add_option("--hdr-scale", o->hdr_scale,
                    "... are multiplied by S (1: off; NeRF-OSR evaluation: 10-30)")
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", o->quiet, "print nothing");
    cmd->footer(convention_text());
    cmd->callback([o] { run_env(*o); });
}

}  // namespace lumigauss::cli
