#include "lumigauss/model/surfel_model.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

float sigmoid(float x) {
    return 1.0f / (1.0f + std::exp(-x));
}

float inverse_sigmoid(float p) {
    return std::log(p / (1.0f - p));
}

int SurfelModel::width(ModelParam p) {
    constexpr int widths[kModelParamCount] = {3, 4, 2, 1, 3, kTransferStored, kTransferStored};
    return widths[int(p)];
}

const char* SurfelModel::name(ModelParam p) {
    constexpr const char* names[kModelParamCount] = {"xyz",    "rotation",   "scaling",   "opacity",
                                                     "albedo", "f_positive", "f_negative"};
    return names[int(p)];
}

SurfelModel SurfelModel::from_raw(std::vector<std::vector<float>> raw) {
    if (raw.size() != std::size_t(kModelParamCount)) throw Error("surfel model: wrong number of arrays");
    SurfelModel m;
    const std::size_t n = raw[0].size() / 3;
    for (ModelParam p : kAllModelParams) {
        if (raw[int(p)].size() != n * std::size_t(width(p)))
            throw Error(std::string("surfel model: array '") + name(p) + "' has the wrong size");
        m.params_[int(p)] = std::move(raw[int(p)]);
    }
    return m;
}

void SurfelModel::transfer_channel0(bool positive, std::size_t i, float out[kTransferCoeffs]) const {
    const auto& t = param(positive ? ModelParam::TransferPositive : ModelParam::TransferNegative);
    for (int k = 0; k < kTransferCoeffs; ++k) out[k] = t[i * kTransferStored + std::size_t(3 * k)];
}

Vec4f SurfelModel::unit_quaternion(std::size_t i) const {
    const auto& q = param(ModelParam::Rotation);
    return normalize_quaternion(Vec4f{q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]});
}

Vec3f SurfelModel::raw_albedo(std::size_t i) const {
    const auto& a = param(ModelParam::Albedo);
    return {a[3 * i], a[3 * i + 1], a[3 * i + 2]};
}

std::vector<Vec3d> SurfelModel::centres() const {
    const std::vector<float>& xyz = param(ModelParam::Xyz);
    std::vector<Vec3d> out(size());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    return out;
}

Vec3f SurfelModel::normal(std::size_t i) const {
    const Mat3f rot = rotation_from_unit_quaternion(unit_quaternion(i));
    return {rot.m[0][2], rot.m[1][2], rot.m[2][2]};
}

void SurfelModel::activated(SurfelBatch<float>& batch) const {
    const std::size_t n = size();
    batch.resize(n);
    const auto& xyz = param(ModelParam::Xyz);
    std::copy(xyz.begin(), xyz.end(), batch.means.begin());
    const auto& rot = param(ModelParam::Rotation);
    std::copy(rot.begin(), rot.end(), batch.quats.begin());
    const auto& s = param(ModelParam::Scaling);
    for (std::size_t i = 0; i < s.size(); ++i) batch.scales[i] = std::exp(s[i]);
    const auto& o = param(ModelParam::Opacity);
    for (std::size_t i = 0; i < n; ++i) batch.opacities[i] = sigmoid(o[i]);
}

void SurfelModel::keep_parameter_rows(std::span<const std::uint8_t> keep) {
    for (ModelParam p : kAllModelParams) {
        std::vector<float>& v = params_[int(p)];
        const auto w = std::size_t(width(p));
        std::size_t out = 0;
        for (std::size_t i = 0; i < keep.size(); ++i) {
            if (!keep[i]) continue;
            if (out != i)
                std::copy_n(v.begin() + std::ptrdiff_t(i * w), w, v.begin() + std::ptrdiff_t(out * w));
            ++out;
        }
        v.resize(out * w);
    }
}

}  // namespace lumigauss
