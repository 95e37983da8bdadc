#include "lumigauss/synth/dataset_writer.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/image.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"

namespace lumigauss::synth {

namespace fs = std::filesystem;

namespace {

// What a synthetic dataset consists of; only these are removed when overwriting.
const char* const kOwnFolders[] = {"images", "masks", "sky_masks", "gt", "env", "sparse"};
const char* const kOwnFiles[] = {"meta.json", "split.csv", "README.md"};
const char* const kGtPasses[] = {"albedo", "normal", "mask", "transient", "sun_visibility"};

void make_dirs(const fs::path& p) {
    std::error_code ec;
    fs::create_directories(p, ec);
    if (ec) throw Error(p.string() + ": cannot create folder (" + ec.message() + ")");
}

// Stores an integer code so that write_png's rounding (lround(v * max)) gives exactly that code back.
float code(int value, int max_code) {
    return float(value) / float(max_code);
}

int quantize(double v, int max_code) {
    return int(std::lround(std::clamp(v, 0.0, 1.0) * max_code));
}

}  // namespace

void prepare_output_dir(const SynthOptions& options) {
    const fs::path root(options.output_dir);
    if (options.output_dir.empty()) throw Error("synth: no output folder given (-o DIR)");
    std::error_code ec;
    if (fs::exists(root, ec) && !fs::is_empty(root, ec)) {
        if (!options.overwrite)
            throw Error(root.string() + ": folder exists and is not empty; choose another or pass --force");
        for (const char* f : kOwnFolders) fs::remove_all(root / f, ec);
        for (const char* f : kOwnFiles) fs::remove(root / f, ec);
    }
    for (const char* f : {"images", "masks", "sky_masks", "env", "sparse/0"}) make_dirs(root / f);
    for (const char* pass : kGtPasses) make_dirs(root / "gt" / pass);
}

std::vector<std::uint8_t> write_photo_files(const std::string& dir, const Photo& photo, const ViewBuffers& b,
                                            bool object_masks) {
    const int w = b.width, h = b.height;
    Image rgb(w, h, 3), albedo(w, h, 3), normal(w, h, 3);
    Image mask(w, h, 1), transient(w, h, 1), static_mask(w, h, 1), sun(w, h, 1), sky(w, h, 1);
    std::vector<std::uint8_t> rgb8(std::size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            for (int c = 0; c < 3; ++c) {
                const int v = encode_pixel(photo.exposure, b.radiance[i][c]);
                rgb8[i * 3 + std::size_t(c)] = std::uint8_t(v);
                rgb.at(x, y, c) = code(v, 255);
                albedo.at(x, y, c) = code(quantize(b.albedo[i][c], 65535), 65535);
                normal.at(x, y, c) = code(quantize(0.5 * (b.normal[i][c] + 1.0), 65535), 65535);
            }
            const int t = quantize(b.transient[i], 255);
            const int coverage = quantize(b.coverage[i], 255);
            mask.at(x, y, 0) = code(coverage, 255);
            sky.at(x, y, 0) = code(255 - coverage, 255);
            transient.at(x, y, 0) = code(t, 255);
            static_mask.at(x, y, 0) =
                object_masks ? code(quantize(b.landmark[i], 255), 255) : code(255 - t, 255);
            sun.at(x, y, 0) = code(quantize(b.sun_visible[i], 255), 255);
        }
    const std::string name = photo.name;
    write_png(dir + "/images/" + name, rgb, 8);
    write_png(dir + "/masks/" + name, static_mask, 8);
    write_png(dir + "/sky_masks/" + name, sky, 8);
    write_png(dir + "/gt/albedo/" + name, albedo, 16);
    write_png(dir + "/gt/normal/" + name, normal, 16);
    write_png(dir + "/gt/mask/" + name, mask, 8);
    write_png(dir + "/gt/transient/" + name, transient, 8);
    write_png(dir + "/gt/sun_visibility/" + name, sun, 8);
    return rgb8;
}

void write_environment(const std::string& dir, const LightCondition& c) {
    const std::string base = dir + "/env/" + c.id;
    write_sh_text(base + "_sh.txt", environment_sh(c));
    const Image pano = environment_panorama(c);
    write_exr(base + ".exr", pano);
    Image preview(pano.width, pano.height, 3);
    for (std::size_t i = 0; i < pano.pixels.size(); ++i)
        preview.pixels[i] = code(encode_pixel(1.0, double(pano.pixels[i])), 255);
    write_png(base + ".png", preview, 8);
}

void write_split_csv(const std::string& dir, const std::vector<Photo>& photos) {
    std::string s = "filename;split\n";
    for (const Photo& p : photos) s += p.name + (p.train ? ";train\n" : ";test\n");
    write_file_atomically(dir + "/split.csv", s);
}

std::vector<std::vector<double>> camera_to_world(const Camera& camera) {
    const Mat3d r = transpose(camera.rotation);
    const Vec3d t = camera.center();
    std::vector<std::vector<double>> m(4, std::vector<double>(4, 0.0));
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m[std::size_t(i)][std::size_t(j)] = r(i, j);
        m[std::size_t(i)][3] = t[i];
    }
    m[3][3] = 1.0;
    return m;
}

}  // namespace lumigauss::synth
