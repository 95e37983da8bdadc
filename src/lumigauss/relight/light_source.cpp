#include "lumigauss/relight/light_source.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;

std::string lower_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

bool starts_with(const std::string& s, const std::string& prefix) {
    return s.compare(0, prefix.size(), prefix) == 0;
}

// A few of the run's photo names, for the error message.
std::string some_names(const TrainedRun& run) {
    std::string list;
    const std::size_t shown = std::min<std::size_t>(run.image_names.size(), 5);
    for (std::size_t i = 0; i < shown; ++i) list += (i ? ", " : "") + run.image_names[i];
    if (run.image_names.size() > shown)
        list += ", ... (" + std::to_string(run.image_names.size()) + " photos)";
    return list.empty() ? "none" : list;
}

// Exact name, else the unique name whose stem (no extension) is `name`; -1 if none or ambiguous.
int find_photo(const TrainedRun& run, const std::string& name) {
    const int exact = run.find_image(name);
    if (exact >= 0) return exact;
    int found = -1;
    for (std::size_t i = 0; i < run.image_names.size(); ++i) {
        fs::path p(run.image_names[i]);
        p.replace_extension();
        if (p.string() == name) {
            if (found >= 0) return -1;
            found = int(i);
        }
    }
    return found;
}

ResolvedLight photo_light(const TrainedRun& run, int index) {
    ResolvedLight light;
    light.kind = LightKind::Photo;
    light.photo_index = index;
    light.source = run.image_names[std::size_t(index)];
    light.sh = run.learned_sh(index);
    if (index < run.sky_residuals.num_images()) light.sky_residual = run.sky_residuals.get(index);
    return light;
}

ResolvedLight file_light(const std::string& path, LightKind kind, const PanoramaOptions& options) {
    ResolvedLight light;
    light.kind = kind;
    light.source = path;
    if (!fs::exists(path)) fail_in_file(path, "missing (the --light file)");
    if (kind == LightKind::ShFile) {
        ShTextLight file = read_sh_text_light(path);
        light.sh = file.sh;
        light.sky_residual = file.sky_residual;
    } else {
        light.sh = panorama_light(path, options, &light.boosted, &light.panorama);
    }
    return light;
}

}  // namespace

const char* light_kind_name(LightKind kind) {
    switch (kind) {
        case LightKind::Photo:
            return "training photo";
        case LightKind::ShFile:
            return "SH file";
        case LightKind::Panorama:
            return "panorama";
    }
    return "?";
}

bool is_ldr_panorama(const std::string& path) {
    const std::string ext = lower_extension(path);
    return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

bool is_panorama_file(const std::string& path) {
    const std::string ext = lower_extension(path);
    return is_ldr_panorama(path) || ext == ".hdr" || ext == ".exr";
}

std::size_t fake_hdr_boost(Image& pano, double threshold, double scale) {
    const int colour = pano.channels == 2 || pano.channels == 4 ? pano.channels - 1 : pano.channels;
    std::size_t changed = 0;
    const std::size_t n = std::size_t(pano.width) * std::size_t(pano.height);
    for (std::size_t p = 0; p < n; ++p)
        for (int c = 0; c < colour; ++c) {
            float& v = pano.pixels[p * std::size_t(pano.channels) + std::size_t(c)];
            if (double(v) > threshold) {
                v = float(double(v) * scale);
                ++changed;
            }
        }
    return changed;
}

ShCoeffs<double> panorama_light(const std::string& path, const PanoramaOptions& options, bool* boosted,
                                Image* pixels) {
    Image pano = read_image(path);
    bool changed = false;
    if (is_ldr_panorama(path) && options.hdr_scale != 1.0)
        changed = fake_hdr_boost(pano, options.hdr_threshold, options.hdr_scale) > 0;
    if (boosted) *boosted = changed;
    try {
        const ShCoeffs<double> sh = project_panorama_to_sh(pano, options.frame);
        if (pixels) *pixels = std::move(pano);
        return sh;
    } catch (const Error& e) {
        fail_in_file(path, e.what());
    }
}

ResolvedLight resolve_light(const std::string& spec, const TrainedRun& run, const PanoramaOptions& options) {
    if (starts_with(spec, "photo:")) {
        const std::string name = spec.substr(6);
        const int index = find_photo(run, name);
        if (index < 0)
            fail_in_file(run.paths.appearance,
                         "no training photo '" + name + "' (photos: " + some_names(run) + ")");
        return photo_light(run, index);
    }
    if (starts_with(spec, "sh:")) return file_light(spec.substr(3), LightKind::ShFile, options);
    if (starts_with(spec, "pano:")) return file_light(spec.substr(5), LightKind::Panorama, options);

    const int index = find_photo(run, spec);
    if (index >= 0) return photo_light(run, index);
    if (fs::is_regular_file(spec)) {
        if (lower_extension(spec) == ".txt") return file_light(spec, LightKind::ShFile, options);
        if (is_panorama_file(spec)) return file_light(spec, LightKind::Panorama, options);
        fail_in_file(spec,
                     "not a known light file: use a .txt SH file (9 rows R G B) or a .hdr/.exr/.png/.jpg "
                     "panorama (or force the kind with sh:FILE / pano:FILE)");
    }
    throw Error("--light '" + spec + "': neither a training photo of " + run.paths.appearance + " (photos: " +
                some_names(run) + ") nor an existing file (.txt SH, or a .hdr/.exr/.png/.jpg panorama)");
}

double dc_luma(const ShCoeffs<double>& sh) {
    return 0.2126 * sh.c[0].x + 0.7152 * sh.c[0].y + 0.0722 * sh.c[0].z;
}

double match_exposure_factor(const ShCoeffs<double>& sh, const TrainedRun& run) {
    if (run.image_names.empty()) throw Error(run.paths.appearance + ": the run has no training photo");
    const double own = dc_luma(sh);
    if (!(own > 0)) throw Error("--match-exposure: the light has no positive mean brightness");
    std::vector<double> lumas;
    for (int i = 0; i < int(run.image_names.size()); ++i) lumas.push_back(dc_luma(run.learned_sh(i)));
    std::nth_element(lumas.begin(), lumas.begin() + std::ptrdiff_t(lumas.size() / 2), lumas.end());
    const double target = lumas[lumas.size() / 2];
    if (!(target > 0))
        throw Error(run.paths.lighting + ": the median learned light has no positive brightness");
    return target / own;
}

ShCoeffs<double> scaled(const ShCoeffs<double>& sh, double factor) {
    ShCoeffs<double> out;
    for (int k = 0; k < kShCount; ++k) out.c[k] = sh.c[k] * factor;
    return out;
}

}  // namespace lumigauss
