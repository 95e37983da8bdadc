#include "lumigauss/io/exif_notes.h"

#include <algorithm>
#include <cstdio>

namespace lumigauss {

namespace {

std::string photos(std::size_t n) {
    return std::to_string(n) + (n == 1 ? " photo" : " photos");
}

std::string exposure_note(const Dataset& scene) {
    std::size_t known = 0;
    double lo = 0, hi = 0;
    for (const View& v : scene.views)
        if (const std::optional<double> ev = v.exif.ev100()) {
            lo = known == 0 ? *ev : std::min(lo, *ev);
            hi = known == 0 ? *ev : std::max(hi, *ev);
            ++known;
        }
    if (known == 0) return {};
    char range[128];
    std::snprintf(range, sizeof range, "EV100 %.2f to %.2f (a spread of %.1f stops)", lo, hi, hi - lo);
    return "EXIF exposure of " + std::to_string(known) + " of " + photos(scene.views.size()) + ": " + range +
           "; each photo's in info --photos and the run's scene.json (train --set exif_exposure=true starts "
           "each photo's light from it)";
}

}  // namespace

std::vector<std::string> exif_notes(const Dataset& scene) {
    std::vector<std::string> notes;
    if (scene.photos_turned_upright > 0)
        notes.push_back(photos(scene.photos_turned_upright) +
                        " turned upright by their EXIF orientation (only upright do they have their camera's "
                        "size), masks of the stored size with them");
    if (scene.orientation_tags_not_applied > 0)
        notes.push_back(
            photos(scene.orientation_tags_not_applied) +
            " with an EXIF orientation tag used as stored: their stored pixels have their camera's "
            "size, and COLMAP calibrates the stored pixels whatever the tag says");
    if (std::string e = exposure_note(scene); !e.empty()) notes.push_back(std::move(e));
    std::size_t damaged = 0;
    const View* first = nullptr;
    for (const View& v : scene.views)
        if (!v.exif.problem.empty()) first = first ? first : &v, ++damaged;
    if (damaged > 0)
        notes.push_back(photos(damaged) +
                        " with EXIF that could not be read (orientation and exposure taken "
                        "as unknown); the first: " +
                        first->exif.problem);
    return notes;
}

}  // namespace lumigauss
