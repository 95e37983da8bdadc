#include "lumigauss/export/splat_format.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "lumigauss/export/baked_colours.h"
#include "lumigauss/export/byte_rounding.h"
#include "lumigauss/export/ply_3dgs.h"
#include "lumigauss/io/atomic_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

void put_float(std::uint8_t* at, float v) {
    std::uint32_t bits = std::bit_cast<std::uint32_t>(v);
    for (int b = 0; b < 4; ++b) at[b] = std::uint8_t((bits >> (8 * b)) & 0xffu);
}

}  // namespace

std::array<std::uint8_t, kSplatBytes> encode_splat(const SplatRecord& s) {
    std::array<std::uint8_t, kSplatBytes> out{};
    for (int k = 0; k < 3; ++k) put_float(&out[std::size_t(4 * k)], s.position[k]);
    for (int k = 0; k < 3; ++k) put_float(&out[std::size_t(12 + 4 * k)], s.scale[k]);
    for (int c = 0; c < 3; ++c) out[std::size_t(24 + c)] = rounded_byte(255.0 * double(s.colour[c]));
    out[27] = rounded_byte(255.0 * double(s.alpha));
    double norm = 0;
    for (int k = 0; k < 4; ++k) norm += double(s.rotation[k]) * double(s.rotation[k]);
    norm = std::sqrt(norm);
    for (int k = 0; k < 4; ++k) {
        const double q = norm > 0 ? double(s.rotation[k]) / norm : (k == 0 ? 1.0 : 0.0);
        out[std::size_t(28 + k)] = rounded_byte(q * 128.0 + 128.0);
    }
    return out;
}

std::vector<SplatRecord> splat_records(const SurfelModel& model, const std::vector<float>& colours) {
    const std::size_t n = model.size();
    if (colours.size() != 3 * n) throw Error("splat_records: colour count does not match the model");
    const auto& xyz = model.param(ModelParam::Xyz);
    const auto& op = model.param(ModelParam::Opacity);
    const auto& sc = model.param(ModelParam::Scaling);
    std::vector<SplatRecord> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        SplatRecord& s = out[i];
        s.position = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
        s.scale = {std::exp(sc[2 * i]), std::exp(sc[2 * i + 1]), kThinScale};
        s.colour = {colours[3 * i], colours[3 * i + 1], colours[3 * i + 2]};
        s.alpha = 1.0f / (1.0f + std::exp(-op[i]));
        s.rotation = model.unit_quaternion(i);
    }
    return out;
}

void write_splat_file(const std::string& path, std::vector<SplatRecord> records) {
    std::stable_sort(records.begin(), records.end(), [](const SplatRecord& a, const SplatRecord& b) {
        return a.scale[0] * a.scale[1] * a.alpha > b.scale[0] * b.scale[1] * b.alpha;
    });
    std::string bytes(records.size() * kSplatBytes, '\0');
    for (std::size_t i = 0; i < records.size(); ++i) {
        const auto e = encode_splat(records[i]);
        std::memcpy(&bytes[i * kSplatBytes], e.data(), kSplatBytes);
    }
    write_file_atomically(path, bytes);
}

}  // namespace lumigauss
