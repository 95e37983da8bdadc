#include "lumigauss/viewer/model_payload.h"

#include <bit>
#include <cstring>
#include <limits>

#include "lumigauss/util/error.h"

namespace lumigauss::view {
namespace {

void put_u32(std::string& out, std::size_t at, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out[at + std::size_t(b)] = char((v >> (8 * b)) & 0xffu);
}

// Little-endian whatever the host order, so the page's Float32Array (little-endian on every browser
// platform) reads the bits unchanged.
void put_f32(std::string& out, std::size_t at, float v) {
    put_u32(out, at, std::bit_cast<std::uint32_t>(v));
}

// Appends one block: `width` floats per surfel taken from `row(i, k)`.
template <typename Row>
std::size_t put_block(std::string& out, std::size_t at, std::size_t n, int width, Row row) {
    for (std::size_t i = 0; i < n; ++i)
        for (int k = 0; k < width; ++k) {
            put_f32(out, at, row(i, k));
            at += 4;
        }
    return at;
}

}  // namespace

std::string encode_model_payload(const SurfelModel& model) {
    const std::size_t n = model.size();
    if (n > std::numeric_limits<std::uint32_t>::max())
        throw Error("view: the model has too many surfels for the viewer payload (" + std::to_string(n) +
                    ")");
    std::string out(kPayloadHeaderBytes + n * std::size_t(kPayloadFloatsPerSurfel) * 4, '\0');
    std::memcpy(out.data(), kPayloadMagic, 8);
    put_u32(out, 8, kPayloadVersion);
    put_u32(out, 12, std::uint32_t(n));
    put_u32(out, 16, std::uint32_t(kPayloadFloatsPerSurfel));
    std::size_t at = kPayloadHeaderBytes;
    for (ModelParam p : {ModelParam::Xyz, ModelParam::Rotation, ModelParam::Scaling, ModelParam::Opacity,
                         ModelParam::Albedo}) {
        const std::vector<float>& v = model.param(p);
        const int w = SurfelModel::width(p);
        at = put_block(out, at, n, w,
                       [&](std::size_t i, int k) { return v[i * std::size_t(w) + std::size_t(k)]; });
    }
    for (bool positive : {true, false}) {
        float t[kTransferCoeffs];
        std::size_t last = n;  // the surfel whose channel 0 is in t
        at = put_block(out, at, n, kTransferCoeffs, [&](std::size_t i, int k) {
            if (i != last) model.transfer_channel0(positive, i, t), last = i;
            return t[k];
        });
    }
    return out;
}

}  // namespace lumigauss::view
