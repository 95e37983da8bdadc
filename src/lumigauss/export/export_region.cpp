#include "lumigauss/export/export_region.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lumigauss/cameras/orbit.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/row_arrays.h"
#include "lumigauss/util/text.h"

namespace lumigauss {

namespace {

Vec3d position(const SurfelModel& model, std::size_t i) {
    const std::vector<float>& xyz = model.param(ModelParam::Xyz);
    return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
}

bool inside(const ExportRegion& region, Vec3d centre, Vec3d p) {
    if (region.radius && !(length(p - centre) <= *region.radius)) return false;
    if (region.box)
        for (int a = 0; a < 3; ++a)
            if (!(p[a] >= (*region.box)[0][a] && p[a] <= (*region.box)[1][a])) return false;
    return true;
}

// The median surfel centre per axis (robust to floaters far out), as the viewer and `render` centre a model.
Vec3d median_centre(const SurfelModel& model) {
    std::vector<Vec3f> points(model.size());
    for (std::size_t i = 0; i < model.size(); ++i) points[i] = position(model, i).cast<float>();
    return point_cloud_centre(points);
}

}  // namespace

RegionedModel apply_export_region(const SurfelModel& model, std::span<const Vec3d> cameras,
                                  const ExportRegion& region) {
    if (region.radius && !(*region.radius > 0))
        throw Error("--crop-radius " + std::to_string(*region.radius) + ": must be a positive distance");
    RegionedModel out;
    out.cameras.assign(cameras.begin(), cameras.end());
    if (model.size() == 0) {
        out.model = model;
        return out;
    }
    out.centre = region.box ? 0.5 * ((*region.box)[0] + (*region.box)[1]) : median_centre(model);
    std::vector<std::uint8_t> keep(model.size(), 1);
    for (std::size_t i = 0; i < model.size(); ++i) keep[i] = inside(region, out.centre, position(model, i));
    out.removed = std::size_t(std::count(keep.begin(), keep.end(), std::uint8_t(0)));
    if (out.removed == model.size())
        throw Error("the crop keeps none of the " + std::to_string(model.size()) +
                    " surfels (their median centre is " + std::to_string(out.centre.x) + "," +
                    std::to_string(out.centre.y) + "," + std::to_string(out.centre.z) + ")");
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (const ModelParam p : kAllModelParams) {
        raw[int(p)] = model.param(p);
        if (out.removed > 0) keep_rows(raw[int(p)], SurfelModel::width(p), keep);
    }
    if (region.recentre) {
        out.translation = -1.0 * out.centre;
        std::vector<float>& xyz = raw[int(ModelParam::Xyz)];
        for (std::size_t i = 0; i < xyz.size(); i += 3)
            for (int a = 0; a < 3; ++a)
                xyz[i + std::size_t(a)] = float(double(xyz[i + std::size_t(a)]) + out.translation[a]);
        for (Vec3d& c : out.cameras) c = c + out.translation;
    }
    out.model = SurfelModel::from_raw(std::move(raw));
    return out;
}

std::array<Vec3d, 2> parse_crop_box(const std::string& text, const std::string& flag) {
    const auto v = parse_number_list(text, 6);
    if (!v) throw Error(flag + " '" + text + "': expected six finite numbers X0,Y0,Z0,X1,Y1,Z1");
    const std::array<Vec3d, 2> box{Vec3d{(*v)[0], (*v)[1], (*v)[2]}, Vec3d{(*v)[3], (*v)[4], (*v)[5]}};
    for (int a = 0; a < 3; ++a)
        if (!(box[0][a] < box[1][a]))
            throw Error(flag + " '" + text + "': each minimum X0,Y0,Z0 must be below its maximum X1,Y1,Z1");
    return box;
}

}  // namespace lumigauss
