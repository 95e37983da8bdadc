#pragma once
// The surfels of a relightable model (the parameters of the official
// `scene/gaussian_model.py:GaussianModel`), as raw (pre-activation) values in structure-of-arrays form,
// without gradients or optimizer state: what rendering, relighting, evaluation, export and the viewer read.
// Training extends it (train/gaussian_model.h) with gradients, Adam groups and densification
// (research/lumigauss_official.md 2.1, 5).
//
// Official tensors and their storage here (row-major float, one row per surfel):
//   _xyz                      N x 3         xyz        identity
//   _rotation                 N x 4         rotation   raw quaternion w x y z (normalised where used)
//   _scaling                  N x 2         scaling    log s_u, log s_v (activation exp)
//   _opacity                  N x 1         opacity    logit (activation sigmoid)
//   _albedo                   N x 3         albedo     raw; colour max(0, Y00 a + 0.5) (surfel_shading.h)
//   _features_dc_positive     N x 1 x 3  \  transfer_positive N x 27, the torch memory order of
//   _features_rest_positive   N x 8 x 3  /  cat((dc, rest), 1): [k * 3 + c], k = SH coefficient, c = channel
//   _features_dc/rest_negative            transfer_negative N x 27, same
// Only channel 0 of a transfer set is ever read (2.1): transfer_channel0() gives those 9 scalars.
#include <cstdint>
#include <span>
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

enum class ModelParam { Xyz, Rotation, Scaling, Opacity, Albedo, TransferPositive, TransferNegative };
inline constexpr int kModelParamCount = 7;
inline constexpr ModelParam kAllModelParams[kModelParamCount] = {
    ModelParam::Xyz,    ModelParam::Rotation,         ModelParam::Scaling,         ModelParam::Opacity,
    ModelParam::Albedo, ModelParam::TransferPositive, ModelParam::TransferNegative};
inline constexpr int kTransferCoeffs = 9;                    // SH degree 2
inline constexpr int kTransferStored = 3 * kTransferCoeffs;  // 27 floats per side as stored officially

class SurfelModel {
  public:
    static int width(ModelParam p);
    static const char* name(ModelParam p);  // the official optimizer group name (transfer: "f_positive"...)

    SurfelModel() = default;
    // Takes raw parameters (a loaded PLY, a checkpoint): one vector per ModelParam, each holding
    // size * width(p) floats. Throws Error naming the array that disagrees.
    static SurfelModel from_raw(std::vector<std::vector<float>> raw);

    std::size_t size() const { return params_[0].size() / 3; }
    std::vector<float>& param(ModelParam p) { return params_[int(p)]; }
    const std::vector<float>& param(ModelParam p) const { return params_[int(p)]; }

    // Channel 0 of surfel i's transfer set: 9 scalars (the only ones the official shading reads).
    void transfer_channel0(bool positive, std::size_t i, float out[kTransferCoeffs]) const;
    // Surfel i's rotation normalised, and its unit normal (the rotation's third column, the side of the
    // positive transfer set), not flipped towards any camera.
    Vec4f unit_quaternion(std::size_t i) const;
    Vec3f raw_albedo(std::size_t i) const;  // before albedo_activation (shading/surfel_shading.h)
    Vec3f normal(std::size_t i) const;
    std::vector<Vec3d> centres() const;  // every surfel's position

    // Geometry and opacity as the rasterizer takes them (exp scales, sigmoid opacity, raw quaternions).
    // Colours are left to the caller: batch.colors is resized to batch.channels per surfel, not written.
    void activated(SurfelBatch<float>& batch) const;

  protected:
    // Keeps rows with keep[i] != 0 of every parameter.
    void keep_parameter_rows(std::span<const std::uint8_t> keep);

    std::vector<float> params_[kModelParamCount];
};

float sigmoid(float x);
float inverse_sigmoid(float p);

}  // namespace lumigauss
