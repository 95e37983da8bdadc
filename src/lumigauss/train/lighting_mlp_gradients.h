#pragma once
// The gradient of a loss with respect to the lighting MLP's parameters (model/lighting_mlp.h): one dense
// array per parameter group, shaped as the group, so that an optimizer (train/adam.h) pairs them generically.
// Gradients accumulate over backward calls until reset; the embedding gradient is dense too (zeros for rows
// not used), as PyTorch's nn.Embedding. Templated on the scalar: float for training, double for
// finite-difference tests.
#include <array>
#include <vector>

#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

template <typename T>
class BasicLightingMlpGradients {
  public:
    BasicLightingMlpGradients() = default;
    explicit BasicLightingMlpGradients(const BasicLightingMlp<T>& mlp) { reset(mlp); }

    // All zero, each group shaped as in `mlp`.
    void reset(const BasicLightingMlp<T>& mlp);

    // Adds dL/dparams for dL/dSH = g_sh of the pass `fwd` of `mlp` (weights, biases and the embedding row
    // fwd.image). Uses the parameters as they are now, which must be those of the forward.
    void backward(const BasicLightingMlp<T>& mlp, const LightingForward<T>& fwd, const ShCoeffs<T>& g_sh);

    std::vector<T>& operator[](MlpGroup g) { return grads_[std::size_t(g)]; }
    const std::vector<T>& operator[](MlpGroup g) const { return grads_[std::size_t(g)]; }

  private:
    std::array<std::vector<T>, kMlpGroupCount> grads_;
};

using LightingMlpGradients = BasicLightingMlpGradients<float>;

}  // namespace lumigauss
