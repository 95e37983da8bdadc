#include "lumigauss/export/spz_format.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/io/atomic_file.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/view_sh.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

void put_u32(std::string& out, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out += char((v >> (8 * b)) & 0xffu);
}

Vec4<double> to_double(Vec4f q) {
    return {q[0], q[1], q[2], q[3]};
}

std::uint8_t to_byte(double v) {
    return std::uint8_t(std::clamp(std::round(v), 0.0, 255.0));
}

// The quaternion (w, x, y, z) as SPZ's smallest three, over the components in x, y, z, w order.
std::uint32_t smallest_three(Vec4<double> wxyz) {
    const double q[4] = {wxyz[1], wxyz[2], wxyz[3], wxyz[0]};
    int largest = 0;
    for (int i = 1; i < 4; ++i)
        if (std::abs(q[i]) > std::abs(q[largest])) largest = i;
    const bool negate = q[largest] < 0;
    std::uint32_t bits = std::uint32_t(largest);
    for (int i = 0; i < 4; ++i) {
        if (i == largest) continue;
        const std::uint32_t sign = (q[i] < 0) != negate ? 1u : 0u;
        const std::uint32_t magnitude =
            std::min<std::uint32_t>(511u, std::uint32_t(511.0 * std::abs(q[i]) * std::sqrt(2.0) + 0.5));
        bits = (bits << 10) | (sign << 9) | magnitude;
    }
    return bits;
}

// round(128 c + 128) to a multiple of `bucket`, clamped (SPZ's default quantisation).
std::uint8_t sh_byte(double c, int bucket) {
    int q = int(std::lround(c * 128.0 + 128.0));
    q = (q + bucket / 2) / bucket * bucket;
    return std::uint8_t(std::clamp(q, 0, 255));
}

std::string gzip(const std::string& data, const std::string& path) {
    z_stream z{};
    if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 9, Z_DEFAULT_STRATEGY) != Z_OK)
        fail_in_file(path, "zlib could not start compressing");
    std::string out(deflateBound(&z, uLong(data.size())) + 64, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.avail_in = uInt(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = uInt(out.size());
    const int result = deflate(&z, Z_FINISH);
    const std::size_t written = z.total_out;
    deflateEnd(&z);
    if (result != Z_STREAM_END) fail_in_file(path, "zlib could not compress the splats");
    out.resize(written);
    return out;
}

}  // namespace

Mat3d rotation_to_y_up(Vec3d up) {
    const Vec3d u = normalize(up), y{0, 1, 0};
    const Vec3d axis = cross(u, y);
    const double s = length(axis), c = dot(u, y);
    if (s < 1e-12) {
        if (c > 0) return Mat3d::identity();
        Mat3d flip = Mat3d::identity();  // 180 degrees about x
        flip(1, 1) = -1, flip(2, 2) = -1;
        return flip;
    }
    const Vec3d k = axis / s;
    // Rodrigues: R = I + sin K + (1 - cos) K^2, K the cross-product matrix of k.
    Mat3d K{};
    K(0, 1) = -k.z, K(0, 2) = k.y, K(1, 0) = k.z, K(1, 2) = -k.x, K(2, 0) = -k.y, K(2, 1) = k.x;
    Mat3d R = Mat3d::identity();
    const Mat3d K2 = K * K;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R(i, j) += s * K(i, j) + (1 - c) * K2(i, j);
    return R;
}

std::string spz_stream(const SurfelModel& model, const SurfelSides& sides, int sh_degree, Vec3d up,
                       std::span<const Vec3d> cameras) {
    if (sh_degree < 0 || sh_degree > 3)
        throw Error("SPZ: SH degree " + std::to_string(sh_degree) + ": use 0, 1, 2 or 3");
    const std::size_t n = model.size();
    const Mat3d R = rotation_to_y_up(up);
    // The model and the cameras in SPZ's frame; the view-dependent colours are computed there.
    SurfelModel turned = model;
    auto& xyz = turned.param(ModelParam::Xyz);
    auto& rotation = turned.param(ModelParam::Rotation);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3d p = R * Vec3d{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
        for (int k = 0; k < 3; ++k) {
            // The fixed-point value written below (from the float), within 24 signed bits.
            const double fixed = std::round(double(float(p[k])) * (1 << kSpzFractionalBits));
            if (!(std::abs(fixed) < double(1 << 23)))
                throw Error("SPZ: surfel " + std::to_string(i) + " lies " + std::to_string(std::abs(p[k])) +
                            " units from the origin: SPZ's 24-bit positions hold less than 2048");
            xyz[3 * i + std::size_t(k)] = float(p[k]);
        }
        const Vec4<double> q =
            quaternion_from_rotation(R * rotation_from_unit_quaternion(to_double(model.unit_quaternion(i))));
        for (int k = 0; k < 4; ++k) rotation[4 * i + std::size_t(k)] = float(q[k]);
    }
    std::vector<Vec3d> turned_cameras;
    for (const Vec3d& c : cameras) turned_cameras.push_back(R * c);
    const std::vector<float> sh = two_sided_view_sh(turned, sides, sh_degree, turned_cameras);
    const std::size_t count = std::size_t(view_sh_coefficients(sh_degree));

    std::string out;
    put_u32(out, kSpzMagic);
    put_u32(out, 3);
    put_u32(out, std::uint32_t(n));
    out += char(sh_degree);
    out += char(kSpzFractionalBits);
    out += char(0);
    out += char(0);
    for (std::size_t i = 0; i < 3 * n; ++i) {
        const std::int32_t fixed = std::int32_t(std::lround(double(xyz[i]) * (1 << kSpzFractionalBits)));
        for (int b = 0; b < 3; ++b) out += char((std::uint32_t(fixed) >> (8 * b)) & 0xffu);
    }
    const auto& opacity = model.param(ModelParam::Opacity);
    for (std::size_t i = 0; i < n; ++i) out += char(to_byte(255.0 * sigmoid(opacity[i])));
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            out += char(to_byte(255.0 * (0.15 * sh[i * count * 3 + std::size_t(c)] + 0.5)));
    const auto& scaling = model.param(ModelParam::Scaling);
    for (std::size_t i = 0; i < n; ++i) {
        out += char(to_byte(16.0 * (scaling[2 * i] + 10.0)));
        out += char(to_byte(16.0 * (scaling[2 * i + 1] + 10.0)));
        out += char(0);  // the surfel's thin axis: as thin as SPZ goes (e^-10)
    }
    for (std::size_t i = 0; i < n; ++i) {
        const Vec4f q = turned.unit_quaternion(i);
        put_u32(out, smallest_three(to_double(q)));
    }
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = 1; k < count; ++k)
            for (int c = 0; c < 3; ++c)
                out += char(sh_byte(sh[(i * count + k) * 3 + std::size_t(c)], k < 4 ? 8 : 16));
    return out;
}

void write_spz_file(const std::string& path, const SurfelModel& model, const SurfelSides& sides,
                    int sh_degree, Vec3d up, std::span<const Vec3d> cameras) {
    const std::string stream = spz_stream(model, sides, sh_degree, up, cameras);
    write_file_atomically(path, gzip(stream, path));
}

}  // namespace lumigauss
