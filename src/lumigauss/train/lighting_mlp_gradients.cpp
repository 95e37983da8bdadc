#include "lumigauss/train/lighting_mlp_gradients.h"

#include <algorithm>
#include <cstddef>

#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

// Backward of y = W x + b: gW += gy x^T, gb += gy, and gx = W^T gy.
template <typename T>
void linear_backward(const std::vector<T>& w, MlpLayerShape s, const T* x, const T* gy, std::vector<T>& gw,
                     std::vector<T>& gb, T* gx) {
    for (int i = 0; i < s.in; ++i) gx[i] = 0;
    for (int o = 0; o < s.out; ++o) {
        const std::size_t r = static_cast<std::size_t>(o) * s.in;
        gb[o] += gy[o];
        for (int i = 0; i < s.in; ++i) gw[r + i] += gy[o] * x[i];
        for (int i = 0; i < s.in; ++i) gx[i] += w[r + i] * gy[o];
    }
}

// Gradient through a ReLU whose output is h: passes where h > 0 (as PyTorch: zero at exactly 0).
template <typename T, std::size_t N>
void relu_backward(const std::array<T, N>& h, std::array<T, N>& g) {
    for (std::size_t i = 0; i < N; ++i)
        if (!(h[i] > T(0))) g[i] = 0;
}

}  // namespace

template <typename T>
void BasicLightingMlpGradients<T>::reset(const BasicLightingMlp<T>& mlp) {
    for (int gi = 0; gi < kMlpGroupCount; ++gi)
        grads_[std::size_t(gi)].assign(mlp.param(MlpGroup(gi)).size(), T(0));
}

template <typename T>
void BasicLightingMlpGradients<T>::backward(const BasicLightingMlp<T>& mlp, const LightingForward<T>& fwd,
                                            const ShCoeffs<T>& g_sh) {
    if (grads_[0].size() != mlp.param(MlpGroup::kEmbedding).size())
        throw Error("lighting MLP gradients: not shaped for this MLP (reset them with it first)");
    auto& self = *this;
    std::array<T, kEnvShOutputs> g_out{};
    for (int k = 0; k < kShCount; ++k)
        for (int ch = 0; ch < 3; ++ch) g_out[env_sh_output(k, ch)] = g_sh.c[k][ch];

    std::array<T, kMlpWidth> g_h2{}, g_h1{};
    linear_backward(mlp.param(MlpGroup::kW3), kMlpLayers[2], fwd.h2.data(), g_out.data(), self[MlpGroup::kW3],
                    self[MlpGroup::kB3], g_h2.data());
    relu_backward(fwd.h2, g_h2);
    linear_backward(mlp.param(MlpGroup::kW2), kMlpLayers[1], fwd.h1.data(), g_h2.data(), self[MlpGroup::kW2],
                    self[MlpGroup::kB2], g_h1.data());
    relu_backward(fwd.h1, g_h1);
    std::array<T, kEmbeddingDim> g_e{};
    linear_backward(mlp.param(MlpGroup::kW1), kMlpLayers[0], fwd.input.data(), g_h1.data(),
                    self[MlpGroup::kW1], self[MlpGroup::kB1], g_e.data());

    T* g_row = &self[MlpGroup::kEmbedding][static_cast<std::size_t>(fwd.image) * kEmbeddingDim];
    for (int i = 0; i < kEmbeddingDim; ++i) g_row[i] += g_e[i];
}

template class BasicLightingMlpGradients<float>;
template class BasicLightingMlpGradients<double>;

}  // namespace lumigauss
