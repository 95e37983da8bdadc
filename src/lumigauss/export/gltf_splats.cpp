#include "lumigauss/export/gltf_splats.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "lumigauss/export/byte_rounding.h"
#include "lumigauss/export/gaussian_splats.h"
#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/view_sh.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using Json = nlohmann::ordered_json;

constexpr std::uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kBinChunk = 0x004E4942;   // "BIN\0"
constexpr int kFloat = 5126, kUnsignedByte = 5121, kArrayBuffer = 34962;
constexpr double kShC0 = 0.28209479177387814;

void append_u32(std::string& out, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out.push_back(char((v >> (8 * b)) & 0xffu));
}

// The binary buffer and the glTF objects that describe it, one buffer view and accessor per attribute.
class GlbBuilder {
  public:
    // Appends `values` (count x width floats) as one attribute; returns its accessor index.
    int add_floats(const std::vector<float>& values, const char* type, std::size_t count) {
        Json accessor = {{"bufferView", add_view(values.data(), values.size() * 4)},
                         {"componentType", kFloat},
                         {"count", count},
                         {"type", type}};
        accessors_.push_back(std::move(accessor));
        return int(accessors_.size()) - 1;
    }
    // Bytes read as normalised unsigned bytes (4 per element, so no stride is needed).
    int add_normalised_bytes(const std::vector<std::uint8_t>& values, const char* type, std::size_t count) {
        Json accessor = {{"bufferView", add_view(values.data(), values.size())},
                         {"componentType", kUnsignedByte},
                         {"normalized", true},
                         {"count", count},
                         {"type", type}};
        accessors_.push_back(std::move(accessor));
        return int(accessors_.size()) - 1;
    }
    Json& accessor(int index) { return accessors_[std::size_t(index)]; }

    std::string glb(Json gltf) const {
        gltf["accessors"] = accessors_;
        gltf["bufferViews"] = views_;
        gltf["buffers"] = Json::array({{{"byteLength", bin_.size()}}});
        std::string json = gltf.dump();
        json.resize((json.size() + 3) / 4 * 4, ' ');
        std::string bin = bin_;
        bin.resize((bin.size() + 3) / 4 * 4, '\0');
        std::string out;
        out.reserve(28 + json.size() + bin.size());
        append_u32(out, kGlbMagic);
        append_u32(out, 2);
        append_u32(out, std::uint32_t(28 + json.size() + bin.size()));
        append_u32(out, std::uint32_t(json.size()));
        append_u32(out, kJsonChunk);
        out += json;
        append_u32(out, std::uint32_t(bin.size()));
        append_u32(out, kBinChunk);
        out += bin;
        return out;
    }

  private:
    int add_view(const void* data, std::size_t bytes) {
        const std::size_t offset = bin_.size();  // every view's length is a multiple of 4
        bin_.append(static_cast<const char*>(data), bytes);
        views_.push_back(
            {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", kArrayBuffer}});
        return int(views_.size()) - 1;
    }

    std::string bin_;
    Json views_ = Json::array(), accessors_ = Json::array();
};

}  // namespace

std::string gltf_splats_glb(const SurfelModel& model, const std::vector<float>& view_sh, int sh_degree) {
    const std::size_t n = model.size();
    if (n == 0) throw Error("glTF: the model has no surfels");
    if (n > std::size_t(std::numeric_limits<std::uint32_t>::max() / 128))
        throw Error("glTF: " + std::to_string(n) + " surfels do not fit one .glb (4 GiB)");
    const std::vector<GaussianSplat> splats = gaussian_splats(model, view_sh, sh_degree);
    const std::size_t rest = 3 * std::size_t(view_sh_coefficients(sh_degree) - 1);

    std::vector<float> position(3 * n), rotation(4 * n), scale(3 * n), opacity(n);
    std::vector<std::uint8_t> colour(4 * n);
    std::vector<double> lo(3, std::numeric_limits<double>::infinity()),
        hi(3, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < n; ++i) {
        const GaussianSplat& s = splats[i];
        for (std::size_t k = 0; k < 3; ++k) {
            position[3 * i + k] = s.position[int(k)];
            lo[k] = std::min(lo[k], double(s.position[int(k)]));
            hi[k] = std::max(hi[k], double(s.position[int(k)]));
        }
        for (std::size_t k = 0; k < 4; ++k)
            rotation[4 * i + k] = s.rotation[int((k + 1) % 4)];  // w x y z -> x y z w
        scale[3 * i] = std::exp(s.log_scale.x);
        scale[3 * i + 1] = std::exp(s.log_scale.y);
        scale[3 * i + 2] = kThinScale;
        opacity[i] = float(1.0 / (1.0 + std::exp(-double(s.opacity))));
        for (int c = 0; c < 3; ++c) {
            const double display = 0.5 + kShC0 * s.dc[c];
            colour[4 * i + std::size_t(c)] =
                rounded_byte(255.0 * srgb_to_linear(float(std::clamp(display, 0.0, 1.0))));
        }
        colour[4 * i + 3] = rounded_byte(255.0 * opacity[i]);
    }
    for (std::size_t k = 0; k < 3; ++k)
        if (!std::isfinite(lo[k]) || !std::isfinite(hi[k]))
            throw Error("glTF: a surfel position is not finite");

    GlbBuilder b;
    Json attributes = Json::object();
    attributes["POSITION"] = b.add_floats(position, "VEC3", n);
    b.accessor(attributes["POSITION"].get<int>())["min"] = {float(lo[0]), float(lo[1]), float(lo[2])};
    b.accessor(attributes["POSITION"].get<int>())["max"] = {float(hi[0]), float(hi[1]), float(hi[2])};
    attributes["KHR_gaussian_splatting:ROTATION"] = b.add_floats(rotation, "VEC4", n);
    attributes["KHR_gaussian_splatting:SCALE"] = b.add_floats(scale, "VEC3", n);
    attributes["KHR_gaussian_splatting:OPACITY"] = b.add_floats(opacity, "SCALAR", n);
    for (int l = 0; l <= sh_degree; ++l)
        for (int m = 0; m <= 2 * l; ++m) {
            const std::size_t k = std::size_t(l * l + m);
            std::vector<float> rgb(3 * n);
            for (std::size_t i = 0; i < n; ++i)
                for (std::size_t c = 0; c < 3; ++c)
                    rgb[3 * i + c] = k == 0 ? splats[i].dc[int(c)] : splats[i].rest[c * (rest / 3) + k - 1];
            attributes["KHR_gaussian_splatting:SH_DEGREE_" + std::to_string(l) + "_COEF_" +
                       std::to_string(m)] = b.add_floats(rgb, "VEC3", n);
        }
    attributes["COLOR_0"] = b.add_normalised_bytes(colour, "VEC4", n);

    Json primitive = {{"mode", 0}, {"attributes", attributes}};
    primitive["extensions"]["KHR_gaussian_splatting"] = {{"kernel", "ellipse"},
                                                         {"colorSpace", "srgb_rec709_display"},
                                                         {"projection", "perspective"},
                                                         {"sortingMethod", "cameraDistance"}};
    Json gltf = {{"asset", {{"version", "2.0"}, {"generator", "lumigauss export"}}},
                 {"extensionsUsed", {"KHR_gaussian_splatting"}},
                 {"scene", 0},
                 {"scenes", {{{"nodes", {0}}}}},
                 {"nodes", {{{"mesh", 0}}}},
                 {"meshes", {{{"primitives", {primitive}}}}}};
    return b.glb(std::move(gltf));
}

void write_gltf_splats(const std::string& path, const SurfelModel& model, const std::vector<float>& view_sh,
                       int sh_degree) {
    std::string bytes;
    try {
        bytes = gltf_splats_glb(model, view_sh, sh_degree);
    } catch (const Error& e) {
        fail_in_file(path, e.what());
    }
    write_file_atomically(path, bytes);
}

}  // namespace lumigauss
