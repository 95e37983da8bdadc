#pragma once
// Unit quaternions (w, x, y, z), w first, Hamilton convention as COLMAP and the 2DGS code.
#include "lumigauss/math/lanes.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

// Rotation matrix of a unit quaternion q = (w, x, y, z).
template <typename T>
LG_HD constexpr Mat3<T> rotation_from_unit_quaternion(Vec4<T> q) {
    const T w = q.x, x = q.y, y = q.z, z = q.w;
    return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
             {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
             {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

template <typename T>
LG_HD inline Vec4<T> normalize_quaternion(Vec4<T> q) {
    const T inv = T(1) / lane_sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    return {q.x * inv, q.y * inv, q.z * inv, q.w * inv};
}

// Backward of rotation_from_unit_quaternion: given dL/dR, returns dL/dq for the unit quaternion q.
template <typename T>
LG_HD constexpr Vec4<T> rotation_from_unit_quaternion_vjp(Vec4<T> q, const Mat3<T>& g) {
    const T w = q.x, x = q.y, y = q.z, z = q.w;
    const T gw = 2 * (-z * g(0, 1) + y * g(0, 2) + z * g(1, 0) - x * g(1, 2) - y * g(2, 0) + x * g(2, 1));
    const T gx = 2 * (y * g(0, 1) + z * g(0, 2) + y * g(1, 0) - 2 * x * g(1, 1) - w * g(1, 2) + z * g(2, 0) +
                      w * g(2, 1) - 2 * x * g(2, 2));
    const T gy = 2 * (-2 * y * g(0, 0) + x * g(0, 1) + w * g(0, 2) + x * g(1, 0) + z * g(1, 2) - w * g(2, 0) +
                      z * g(2, 1) - 2 * y * g(2, 2));
    const T gz = 2 * (-2 * z * g(0, 0) - w * g(0, 1) + x * g(0, 2) + w * g(1, 0) - 2 * z * g(1, 1) +
                      y * g(1, 2) + x * g(2, 0) + y * g(2, 1));
    return {gw, gx, gy, gz};
}

// Backward of normalize_quaternion: the raw parameter gets (I - q̂q̂ᵀ) g / |q|.
template <typename T>
LG_HD inline Vec4<T> normalize_quaternion_vjp(Vec4<T> raw, Vec4<T> g_unit) {
    const T norm = lane_sqrt(raw.x * raw.x + raw.y * raw.y + raw.z * raw.z + raw.w * raw.w);
    const Vec4<T> u{raw.x / norm, raw.y / norm, raw.z / norm, raw.w / norm};
    const T proj = u.x * g_unit.x + u.y * g_unit.y + u.z * g_unit.z + u.w * g_unit.w;
    return {(g_unit.x - proj * u.x) / norm, (g_unit.y - proj * u.y) / norm, (g_unit.z - proj * u.z) / norm,
            (g_unit.w - proj * u.w) / norm};
}

// Unit quaternion (w >= 0) of a rotation matrix, by Shepperd's method (pivot on the largest diagonal term
// so the square root never sees a small argument).
template <typename T>
LG_HD inline Vec4<T> quaternion_from_rotation(const Mat3<T>& R) {
    const T tr = R(0, 0) + R(1, 1) + R(2, 2);
    Vec4<T> q;
    if (tr >= R(0, 0) && tr >= R(1, 1) && tr >= R(2, 2)) {
        const T s = std::sqrt(T(1) + tr) * 2;
        q = {s / 4, (R(2, 1) - R(1, 2)) / s, (R(0, 2) - R(2, 0)) / s, (R(1, 0) - R(0, 1)) / s};
    } else if (R(0, 0) >= R(1, 1) && R(0, 0) >= R(2, 2)) {
        const T s = std::sqrt(T(1) + R(0, 0) - R(1, 1) - R(2, 2)) * 2;
        q = {(R(2, 1) - R(1, 2)) / s, s / 4, (R(0, 1) + R(1, 0)) / s, (R(0, 2) + R(2, 0)) / s};
    } else if (R(1, 1) >= R(2, 2)) {
        const T s = std::sqrt(T(1) + R(1, 1) - R(0, 0) - R(2, 2)) * 2;
        q = {(R(0, 2) - R(2, 0)) / s, (R(0, 1) + R(1, 0)) / s, s / 4, (R(1, 2) + R(2, 1)) / s};
    } else {
        const T s = std::sqrt(T(1) + R(2, 2) - R(0, 0) - R(1, 1)) * 2;
        q = {(R(1, 0) - R(0, 1)) / s, (R(0, 2) + R(2, 0)) / s, (R(1, 2) + R(2, 1)) / s, s / 4};
    }
    if (q.x < 0) q = {-q.x, -q.y, -q.z, -q.w};
    return q;
}

}  // namespace lumigauss
