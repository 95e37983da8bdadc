#pragma once
// `export --crop-radius`, `--crop-box` and `--recentre`: which surfels go into an exported file and where its
// origin lies, for engines and editors that place a model at its origin and choke on far-away floaters. A
// surfel is kept when its centre is inside every crop given; recentring translates the kept model (and the
// camera centres its colours are baked for) so that the region's centre is the origin. Distances and boxes
// are in the world as trained, before any --orient turn.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

struct ExportRegion {
    std::optional<double> radius;             // keep centres within this distance of the region's centre
    std::optional<std::array<Vec3d, 2>> box;  // keep centres inside [min, max] (inclusive), world axes
    bool recentre = false;                    // translate so that the region's centre is the origin
    bool any() const { return radius || box || recentre; }
};

struct RegionedModel {
    SurfelModel model;           // the surfels kept, translated when recentred
    std::vector<Vec3d> cameras;  // the camera centres, translated alike
    Vec3d centre{};              // the region's centre: the box's centre, else the median surfel centre
    Vec3d translation{};         // added to every position (-centre when recentred, else 0)
    std::size_t removed = 0;     // surfels outside the crop
};

// Throws Error when a crop keeps no surfel, the radius is not positive, or a box is empty.
RegionedModel apply_export_region(const SurfelModel& model, std::span<const Vec3d> cameras,
                                  const ExportRegion& region);

// "X0,Y0,Z0,X1,Y1,Z1" (each min below its max). Throws Error naming `flag` otherwise.
std::array<Vec3d, 2> parse_crop_box(const std::string& text, const std::string& flag);

}  // namespace lumigauss
