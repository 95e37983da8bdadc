#include "lumigauss/export/spz_format.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lumigauss/export/byte_rounding.h"
#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/export/world_turn.h"
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
    return rotation_taking(up, {0, 1, 0});
}

std::string spz_stream(const SurfelModel& model, const SurfelSides& sides, int sh_degree, Vec3d up,
                       std::span<const Vec3d> cameras) {
    if (sh_degree < 0 || sh_degree > 3)
        throw Error("SPZ: SH degree " + std::to_string(sh_degree) + ": use 0, 1, 2 or 3");
    const std::size_t n = model.size();
    // The model and the cameras in SPZ's frame; the view-dependent colours are computed there.
    const TurnedWorld world = turn_world(model, cameras, rotation_to_y_up(up));
    const SurfelModel& turned = world.model;
    const auto& xyz = turned.param(ModelParam::Xyz);
    for (std::size_t i = 0; i < 3 * n; ++i) {
        // The fixed-point value written below, within 24 signed bits.
        const double fixed = std::round(double(xyz[i]) * (1 << kSpzFractionalBits));
        if (!(std::abs(fixed) < double(1 << 23)))
            throw Error("SPZ: surfel " + std::to_string(i / 3) + " lies " + std::to_string(std::abs(xyz[i])) +
                        " units from the origin: SPZ's 24-bit positions hold less than 2048");
    }
    const std::vector<float> sh = two_sided_view_sh(turned, sides, sh_degree, world.cameras);
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
    for (std::size_t i = 0; i < n; ++i) out += char(rounded_byte(255.0 * sigmoid(opacity[i])));
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            out += char(rounded_byte(255.0 * (0.15 * sh[i * count * 3 + std::size_t(c)] + 0.5)));
    const auto& scaling = model.param(ModelParam::Scaling);
    for (std::size_t i = 0; i < n; ++i) {
        out += char(rounded_byte(16.0 * (scaling[2 * i] + 10.0)));
        out += char(rounded_byte(16.0 * (scaling[2 * i + 1] + 10.0)));
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
