#include "lumigauss/export/world_turn.h"

#include <cmath>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

Mat3d rotation_taking(Vec3d from, Vec3d to) {
    const Vec3d u = normalize(from), v = normalize(to);
    const Vec3d axis = cross(u, v);
    const double s = length(axis), c = dot(u, v);
    Vec3d k;
    if (s < 1e-12) {
        if (c > 0) return Mat3d::identity();
        // Opposite: half a turn about any axis perpendicular to u.
        k = normalize(cross(u, std::abs(u.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}));
    } else {
        k = axis / s;
    }
    // Rodrigues: R = I + sin K + (1 - cos) K^2, K the cross-product matrix of the unit axis k.
    Mat3d K{};
    K(0, 1) = -k.z, K(0, 2) = k.y, K(1, 0) = k.z, K(1, 2) = -k.x, K(2, 0) = -k.y, K(2, 1) = k.x;
    const Mat3d K2 = K * K;
    Mat3d R = Mat3d::identity();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R(i, j) += s * K(i, j) + (1 - c) * K2(i, j);
    return R;
}

TurnedWorld turn_world(const SurfelModel& model, std::span<const Vec3d> cameras, const Mat3d& R) {
    TurnedWorld turned{model, {}};
    auto& xyz = turned.model.param(ModelParam::Xyz);
    auto& rotation = turned.model.param(ModelParam::Rotation);
    for (std::size_t i = 0; i < model.size(); ++i) {
        const Vec3d p = R * Vec3d{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
        for (int k = 0; k < 3; ++k) xyz[3 * i + std::size_t(k)] = float(p[k]);
        const Vec4f q = model.unit_quaternion(i);
        const Vec4<double> turned_q =
            quaternion_from_rotation(R * rotation_from_unit_quaternion(Vec4<double>{q[0], q[1], q[2], q[3]}));
        for (int k = 0; k < 4; ++k) rotation[4 * i + std::size_t(k)] = float(turned_q[k]);
    }
    for (const Vec3d& c : cameras) turned.cameras.push_back(R * c);
    return turned;
}

ExportOrientation parse_export_orientation(const std::string& text) {
    if (text == "none") return ExportOrientation::None;
    if (text == "y-up") return ExportOrientation::YUp;
    if (text == "y-down") return ExportOrientation::YDown;
    throw Error("--orient '" + text + "': use none, y-up or y-down");
}

Mat3d orientation_rotation(ExportOrientation orientation, Vec3d up) {
    if (orientation == ExportOrientation::YUp) return rotation_taking(up, {0, 1, 0});
    if (orientation == ExportOrientation::YDown) return rotation_taking(up, {0, -1, 0});
    return Mat3d::identity();
}

}  // namespace lumigauss
