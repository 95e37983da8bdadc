#pragma once
// Small fixed-size vectors and 3x3 matrices, templated on the scalar so that the same formulas run in
// float (renderers) and double (reference implementations and finite-difference tests).
#include <cmath>

#include "lumigauss/math/hd.h"

namespace lumigauss {

template <typename T>
struct Vec2 {
    T x{}, y{};
    LG_HD constexpr T& operator[](int i) { return i == 0 ? x : y; }
    LG_HD constexpr T operator[](int i) const { return i == 0 ? x : y; }
};

template <typename T>
struct Vec3 {
    T x{}, y{}, z{};
    LG_HD constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    LG_HD constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    template <typename U>
    LG_HD constexpr Vec3<U> cast() const {
        return {static_cast<U>(x), static_cast<U>(y), static_cast<U>(z)};
    }
};

template <typename T>
struct Vec4 {
    T x{}, y{}, z{}, w{};
    LG_HD constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : (i == 2 ? z : w)); }
    LG_HD constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : (i == 2 ? z : w)); }
};

using Vec2f = Vec2<float>;
using Vec3f = Vec3<float>;
using Vec4f = Vec4<float>;
using Vec3d = Vec3<double>;

template <typename T>
LG_HD constexpr Vec2<T> operator+(Vec2<T> a, Vec2<T> b) {
    return {a.x + b.x, a.y + b.y};
}
template <typename T>
LG_HD constexpr Vec2<T> operator-(Vec2<T> a, Vec2<T> b) {
    return {a.x - b.x, a.y - b.y};
}
template <typename T>
LG_HD constexpr Vec2<T> operator*(T s, Vec2<T> a) {
    return {s * a.x, s * a.y};
}

template <typename T>
LG_HD constexpr Vec3<T> operator+(Vec3<T> a, Vec3<T> b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <typename T>
LG_HD constexpr Vec3<T> operator-(Vec3<T> a, Vec3<T> b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <typename T>
LG_HD constexpr Vec3<T> operator-(Vec3<T> a) {
    return {-a.x, -a.y, -a.z};
}
template <typename T>
LG_HD constexpr Vec3<T> operator*(T s, Vec3<T> a) {
    return {s * a.x, s * a.y, s * a.z};
}
template <typename T>
LG_HD constexpr Vec3<T> operator*(Vec3<T> a, T s) {
    return {s * a.x, s * a.y, s * a.z};
}
template <typename T>
LG_HD constexpr Vec3<T> operator/(Vec3<T> a, T s) {
    return {a.x / s, a.y / s, a.z / s};
}
template <typename T>
LG_HD constexpr Vec3<T>& operator+=(Vec3<T>& a, Vec3<T> b) {
    a.x += b.x, a.y += b.y, a.z += b.z;
    return a;
}
template <typename T>
LG_HD constexpr Vec3<T> hadamard(Vec3<T> a, Vec3<T> b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}

template <typename T>
LG_HD constexpr T dot(Vec3<T> a, Vec3<T> b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T>
LG_HD constexpr Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T>
LG_HD inline T length(Vec3<T> a) {
    return std::sqrt(dot(a, a));
}
template <typename T>
LG_HD inline Vec3<T> normalize(Vec3<T> a) {
    return a / length(a);
}

// Row-major 3x3 matrix: m[r] is row r.
template <typename T>
struct Mat3 {
    Vec3<T> m[3]{};
    LG_HD static constexpr Mat3 identity() { return {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; }
    LG_HD static constexpr Mat3 from_columns(Vec3<T> c0, Vec3<T> c1, Vec3<T> c2) {
        return {{{c0.x, c1.x, c2.x}, {c0.y, c1.y, c2.y}, {c0.z, c1.z, c2.z}}};
    }
    LG_HD constexpr Vec3<T> row(int r) const { return m[r]; }
    LG_HD constexpr Vec3<T> col(int c) const { return {m[0][c], m[1][c], m[2][c]}; }
    LG_HD constexpr T operator()(int r, int c) const { return m[r][c]; }
    LG_HD constexpr T& operator()(int r, int c) { return m[r][c]; }
    template <typename U>
    LG_HD constexpr Mat3<U> cast() const {
        return {{m[0].template cast<U>(), m[1].template cast<U>(), m[2].template cast<U>()}};
    }
};
using Mat3f = Mat3<float>;
using Mat3d = Mat3<double>;

template <typename T>
LG_HD constexpr Vec3<T> operator*(const Mat3<T>& a, Vec3<T> v) {
    return {dot(a.m[0], v), dot(a.m[1], v), dot(a.m[2], v)};
}
template <typename T>
LG_HD constexpr Mat3<T> transpose(const Mat3<T>& a) {
    return Mat3<T>::from_columns(a.m[0], a.m[1], a.m[2]);
}
template <typename T>
LG_HD constexpr Mat3<T> operator*(const Mat3<T>& a, const Mat3<T>& b) {
    Mat3<T> r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
    return r;
}

}  // namespace lumigauss
