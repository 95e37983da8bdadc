// README.md of a synthetic dataset: what is in it and every convention needed to use it, in the words of
// data/plaza's README where the conventions are the same (they are, for every file an evaluation reads).
#include <cstdio>
#include <string>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/synth/dataset_writer.h"

namespace lumigauss::synth {

namespace {

template <typename... Args>
std::string format(const char* fmt, Args... args) {
    char buf[1024];
    const int n = std::snprintf(buf, sizeof buf, fmt, args...);
    return std::string(buf, std::size_t(n));
}

std::string header(const MetaInputs& in) {
    const SynthOptions& o = *in.options;
    int n_train = 0, n_test = 0, n_transient = 0;
    for (const Photo& p : *in.photos) (p.train ? n_train : n_test) += 1, n_transient += p.n_transients > 0;
    std::string train_ids, test_ids;
    for (const LightCondition& c : *in.conditions) (c.split == "train" ? train_ids : test_ids) += c.id + ", ";
    if (train_ids.size() > 1) train_ids.resize(train_ids.size() - 2);
    if (test_ids.size() > 1) test_ids.resize(test_ids.size() - 2);
    std::string s = format("# Synthetic relighting scene: `%s`\n\n", o.scene.c_str());
    s += "Procedural landmark (" + in.landmark->description +
         ") rendered by `lumigauss synth`, a small CPU ray tracer, and photographed \"tourist style\" "
         "under many lightings. Ground-truth albedo, normals, masks, sun visibility and environment SH are "
         "provided. ";
    s += format(
        "Generation parameters: `--landmark %s --width %d --height %d --train %d --test %d --seed %llu "
        "--transients %g --spp-side %d --points %d --gt-surfels %d`.\n\n",
        o.scene.c_str(), o.width, o.height, o.n_train, o.n_test, static_cast<unsigned long long>(o.seed),
        o.transient_fraction, o.samples_per_side, o.point_candidates, o.gt_surfels);
    s += format(
        "* %d training images (%d of them contain random \"pedestrian\" transients), %d test images.\n",
        n_train, n_transient, n_test);
    s += "* Test images = novel view **and** novel lighting: their conditions (" + test_ids +
         ") are never used by a training image. Training conditions: " + train_ids + ".\n";
    s += format("* Resolution %dx%d, %d jittered-stratified samples per pixel (%dx%d), box-filtered.\n",
                o.width, o.height, o.samples_per_side * o.samples_per_side, o.samples_per_side,
                o.samples_per_side);
    s += "* All materials are purely Lambertian; albedo textures are procedural (bricks, tiles, stripes, "
         "noise).\n"
         "* Lighting: a smooth sky that is exactly a degree-2 SH (blue zenith, brighter horizon, circumsolar "
         "glow, "
         "dark ground below the horizon; ~20% overcast skies) plus a sun disc of 1.0 deg diameter.\n"
         "* Same seed, same options: byte-identical files.\n\n";
    return s;
}

// The layout table: one row per file kind, as in data/plaza's README.
const char* const kLayoutRows[][2] = {
    {"`images/NAME.png`", "8-bit sRGB RGB photo (sky visible). NAME = `train_XXXX` or `test_XXXX`"},
    {"`gt/albedo/NAME.png`",
     "16-bit RGB PNG, **linear** albedo, value/65535, mean over the pixel's samples. Sky = 0"},
    {"`gt/normal/NAME.png`",
     "16-bit RGB PNG, **world-space** unit normal n encoded as (n+1)/2, value/65535 (mean over"
     " samples, so edges are shorter than unit). Sky = (0.5,0.5,0.5) (n=0)"},
    {"`gt/mask/NAME.png`",
     "8-bit gray, pixel coverage of any geometry (building, ground, pedestrians): 255 = "
     "geometry, 0 = sky; anti-aliased edges have intermediate values"},
    {"`gt/transient/NAME.png`",
     "8-bit gray, coverage of transient pedestrians (255 = transient). All-zero for images "
     "without transients (always for test)"},
    {"`gt/sun_visibility/NAME.png`",
     "8-bit gray, fraction of the pixel's samples lit by the sun (surface faces the sun and "
     "the shadow ray is unblocked); 0 for sky. Not in data/plaza"},
    {"`gt/surfels.ply`",
     "the static scene (pedestrians excluded) as 2D Gaussian surfels in the 2DGS PLY layout, SH degree 0, "
     "colour = linear albedo: ground-truth geometry and albedo (see below). Not in data/plaza; absent with "
     "`--gt-surfels 0`"},
    {"`env/COND.exr`",
     "environment radiance, equirectangular 128x64, float32 OpenEXR (the sky SH in every "
     "pixel, the sun's power in one pixel)"},
    {"`env/COND.png`",
     "8-bit sRGB preview of the same map (exposure 1, clipped). Not in data/plaza (which has "
     "`env/COND.hdr`)"},
    {"`env/COND_sh.txt`",
     "9 lines `R G B`: radiance SH coefficients L_lm of that environment (sun included)"},
    {"`masks/NAME.png`",
     "8-bit gray static-scene training mask, as users supply with photo collections: 255 = "
     "use, 0 = transient (pedestrian); = 255 - gt/transient. With `synth --object-masks`: the landmark's "
     "coverage instead (255 on the building, 0 on the ground, pedestrians and sky), to be trained with "
     "`--set mask_mode=object`"},
    {"`sky_masks/NAME.png`",
     "8-bit gray sky mask, as a semantic segmentation of the photo gives it: 255 = sky (fraction of "
     "the pixel that sees no geometry), 0 = anything else; = 255 - gt/mask"},
    {"`split.csv`", "`filename;split` (train/test) for every image"},
    {"`sparse/0/{cameras,images,points3D}.txt`",
     "COLMAP text model (PINHOLE, one camera per image, camera id = image id)"},
    {"`meta.json`",
     "per image: name, image_id, split, condition, exposure, fx fy cx cy, width height, c2w "
     "(4x4, OpenCV), has_transients, n_transients; conditions (with `sky_sh`, the sky without "
     "the sun); bbox; conventions"},
};

std::string gt_surfels_section(const MetaInputs& in) {
    if (!in.gt_surfels || in.gt_surfels->model.size() == 0) return "";
    const GtSurfels& g = *in.gt_surfels;
    std::string s = format(
        "**Ground-truth surfels** (`gt/surfels.ply`): %zu 2D Gaussian surfels (2DGS PLY layout: `x y z`, "
        "`f_dc_0..2`, `opacity` as a logit, `scale_0 scale_1` as logs, `rot_0..3` a w-first quaternion) "
        "modelling the static scene's surfaces, about half on the landmark and half on the ground. One "
        "surfel "
        "sits at the centre of each cell of a grid laid over each face (cells of equal area, so the surfels "
        "are uniform by area): %.3f m cells on the landmark's faces; on the ground, rings of %.3f m cells "
        "within %.1f m of the landmark's centre (every camera is inside) and cells growing with the cube of "
        "the distance beyond, out to the ground's edge. A cell is kept when some image (train or test) sees "
        "its centre or a point near one of its corners (facing the camera, in frame, unoccluded by the "
        "static scene). ",
        g.model.size(), g.cell, g.ground_cell, g.near_radius);
    s += format(
        "Each surfel lies in its surface: the third column of its rotation is the true outward normal, the "
        "first runs along its cell's first side; its scales are %.2f x its cell's side lengths, so that "
        "neighbours overlap and surfaces render closed; opacity %.2f. Colour is view-independent (SH degree "
        "0): the true **linear** albedo averaged over the surfel's cell (%dx%d points), `f_dc = (albedo - "
        "0.5) "
        "/ 0.28209479`, i.e. `0.5 + C0 * f_dc = albedo`. So `lumigauss render --ply gt/surfels.ply --scene "
        "DIR` renders images comparable to `gt/albedo` (linear; black where the sky is), up to texture "
        "detail finer than the cells and the surfel approximation at geometry edges: at the native "
        "resolution the rasterizer draws every surfel at least as a 0.7-pixel blob, which widens thin "
        "features and foreground edges by up to a pixel (render at a multiple of the resolution and "
        "box-filter down to compare with `gt/albedo`, itself a box-filtered pixel).\n\n",
        kScalePerCell, kOpacity, kAlbedoSamples, kAlbedoSamples);
    return s;
}

std::string conventions(const MetaInputs& in) {
    const Vec3d lo = in.landmark->bbox_lo, hi = in.landmark->bbox_hi;
    std::string s = "## Conventions\n\n";
    s += format(
        "**World frame**: right-handed, +Z up, metres. Ground plane z = 0 (a 600 m square). The landmark's "
        "main entrance faces -Y. Landmark bounding box (min, max): [[%.2f, %.2f, %.2f], [%.2f, %.2f, "
        "%.2f]].\n\n",
        lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    s +=
        R"(**Cameras**: OpenCV/COLMAP convention: camera x right, y down, z forward. `c2w` in meta.json maps
camera coordinates to world (`X_world = R X_cam + t`). COLMAP `images.txt` holds world-to-camera `QW QX QY QZ
TX TY TZ` (`X_cam = R(q) X_world + t`, Hamilton quaternion, w >= 0). Pinhole: `u = fx*x/z + cx`, `v = fy*y/z +
cy` with the origin at the top-left corner of the top-left pixel (pixel centres at +0.5); cx = W/2, cy = H/2,
fx = fy = W * f / 36 with a 35 mm-equivalent focal length f uniform in [28, 42] mm. No distortion. Viewpoints:
azimuth within +-110 deg of the front (-Y), 70% at eye height (1.5-2 m), 30% raised (3 m up to half the
landmark's height), distance 0.5-1x the one at which the landmark's bounding sphere fills the view, a target
jittered about the landmark, roll within +-3 deg.

**Radiance scale and exposure**: env maps and rendered radiance share one linear unit. For every image
`pixel_8bit = round(255 * srgb_encode(clip(exposure * radiance, 0, 1)))`, with the standard piecewise sRGB
OETF (12.92x below 0.0031308, else 1.055 x^(1/2.4) - 0.055), applied to the mean radiance of the pixel's
samples. `exposure` is per image in meta.json: uniform in [0.75, 1.35] for training images, exactly 1.0 for
test images. No other tone mapping. Each condition is scaled (`strength`) so that the largest irradiance over
upward and sideways normals is 3.8, as in data/plaza.

**Shading** (what the ray tracer computes, exactly): a surface point with albedo rho and normal n has radiance
`rho/pi * (E_sky(n) + V_sun * sun_power * max(0, n.s))`, where `E_sky(n) = sum_lm A_l L_lm Y_lm(n)` (A_0 = pi,
A_1 = 2pi/3, A_2 = pi/4) is the Ramamoorthi-Hanrahan irradiance of the sky SH `sky_sh` (meta.json) -- exact,
since the sky radiance *is* that degree-2 SH -- and `V_sun` is 1 when a ray towards the sun direction `s`
leaves the scene (hard shadows, pedestrians included). The sky is **not** occluded (no ambient occlusion) and
there are no interreflections: so on surfaces the sun reaches, `radiance = rho/pi * (E_sky(n) + sun_power *
max(0, n.s))` holds to 8-bit quantisation, and in sun shadow `radiance = rho/pi * E_sky(n)`. A camera ray that
misses the scene sees the sky SH radiance (clamped at 0; the SH is non-negative by construction) plus the sun
disc.

**The sun and the SH**: the sun is a disc of 1.0 deg diameter and uniform radiance around `sun_dir_world`,
with `sun_power_rgb` = its radiance integrated over the disc, i.e. the irradiance it gives a surface facing
it. Its direction is snapped to the centre of a pixel of the 128x64 map (`sun_env_pixel_rowcol`).
`env/COND_sh.txt` is `sky_sh` plus the SH projection of the disc (`sun_power * Y_lm(s)`, times the disc's band
factor, within 6e-5 of 1). With the env SH the irradiance of an unoccluded surface is `E(n) ~= sum_lm A_l L_lm
Y_lm(n)`: exact for the sky, the order-2 truncation of `sun_power * max(0, n.s)` for the sun (see
`irradiance_up_numeric`, exact, against `irradiance_up_sh` in meta.json conditions).

**Environment maps** (`env/`): equirectangular, 128 columns x 64 rows, row 0 = top = zenith (+Z). For pixel
(row i, column j): `theta = pi*(i+0.5)/H` (polar angle from +Z), `phi = 2*pi*(0.5 - (j+0.5)/W)`, `d =
(sin(theta)cos(phi), sin(theta)sin(phi), cos(theta))` in the world frame above. So the image centre column
looks along **+X**, a quarter width left of centre is **+Y**, a quarter right of centre is **-Y**, both edges
are **-X**; moving right in the image decreases the azimuth atan2(y,x) (Blender's Environment Texture
convention, as data/plaza). Every pixel holds the sky SH radiance at its centre direction; the sun pixel also
holds `sun_power / dOmega` with the exact pixel solid angle `dOmega = (2pi/W) (cos(theta-pi/2H) -
cos(theta+pi/2H))`.

**SH** (`env/COND_sh.txt`, `sky_sh`): 9 lines `R G B` in the order (l,m) =
(0,0),(1,-1),(1,0),(1,1),(2,-2),(2,-1), (2,0),(2,1),(2,2), real basis Y00 = 0.282095, Y1-1 = 0.488603 y, Y10 =
0.488603 z, Y11 = 0.488603 x, Y2-2 = 1.092548 xy, Y2-1 = 1.092548 yz, Y20 = 0.315392 (3z^2-1), Y21 = 1.092548
xz, Y22 = 0.546274 (x^2-y^2) (no Condon-Shortley phase). Radiance coefficients L_lm: L(d) = sum_lm L_lm
Y_lm(d).

)";
    s += format(
        "**COLMAP sparse model**: all images are registered with exact poses (`images.txt`); only training "
        "images carry 2D observations. `points3D.txt`: %d points sampled on the surfaces (half area-weighted "
        "on the landmark, half uniformly on the ground within 1.3x the farthest training camera's distance), "
        "kept when seen (in frame, viewed less than 87 deg from the normal, unoccluded by a ray test, "
        "pedestrians included) by >= 2 training images; TRACK lists those images. Positions carry Gaussian "
        "noise (sigma = %.4f m per axis, i.e. 0.5%% of the %.1f m scene diagonal in RMS length); the 2D "
        "observations are the exact projections of the noise-free points; ERROR is the resulting RMS "
        "reprojection error in pixels; RGB = mean of the 8-bit training pixels at the observations.\n\n",
        in.n_points, in.noise_sigma, in.scene_diag);
    s += gt_surfels_section(in);
    s += "**Transients**: 2-5 pedestrians (a cylinder or box body with a sphere head, random colours) stand "
         "between "
         "camera and landmark in some training images only; they cast shadows (not masked) and are included "
         "in "
         "`gt/mask`, `gt/albedo`, `gt/normal` and `gt/transient`, and excluded by `masks/`.\n\n";
    return s;
}

std::string conditions_table(const MetaInputs& in) {
    std::string s =
        "## Lighting conditions\n\n| id | split | sky | sun elevation, azimuth atan2(y,x) | sun power "
        "(RGB) | strength |\n| --- | --- | --- | --- | --- | --- |\n";
    for (const LightCondition& c : *in.conditions)
        s += format("| %s | %s | %s | %.1f deg, %.1f deg | %.3f %.3f %.3f | %.4g |\n", c.id.c_str(),
                    c.split.c_str(), c.overcast ? "overcast" : "clear", sun_elevation_deg(c),
                    sun_azimuth_deg(c), c.sun_power.x, c.sun_power.y, c.sun_power.z, c.strength);
    return s;
}

}  // namespace

std::string layout() {
    std::string s = "## Layout\n\n| path | content |\n| --- | --- |\n";
    for (const auto& row : kLayoutRows) s += std::string("| ") + row[0] + " | " + row[1] + " |\n";
    return s + "\n";
}

void write_readme(const std::string& dir, const MetaInputs& in) {
    write_file_atomically(dir + "/README.md", header(in) + layout() + conventions(in) + conditions_table(in));
}

}  // namespace lumigauss::synth
