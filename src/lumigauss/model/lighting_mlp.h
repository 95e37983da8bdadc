#pragma once
// The official LumiGauss lighting model (research/lumigauss_official.md 2.2, `scene/mlp.py:MLP`): a learned
// embedding per training photo and a small MLP that maps it to that photo's environment SH.
//
//   e = embedding[image]                                   (24)
//   h1 = relu(W1 e + b1)                                   (64)
//   h2 = relu(W2 h1 + b2)                                  (64)
//   out = W3 h2 + b3                                       (27, no output activation)
//   sh.c[k][ch] = out[ch * 9 + k]                          (official `outputs.reshape(3, 9)`: row = RGB
//                                                           channel, column = SH index k in sh.h order)
//
// Parameters are flat row-major arrays, one per group (the embedding table num_images x 24, then W (out x in,
// PyTorch layout) and b of each layer), so that an optimizer (train/adam.h) treats them generically. This is
// the model alone: its gradients live with whoever optimises it (train/lighting_mlp_gradients.h).
//
// Initialisation follows PyTorch's defaults in distribution: embedding ~ N(0, 1); every Linear weight and
// bias ~ U(-1/sqrt(fan_in), 1/sqrt(fan_in)). The draws come from a seeded std::mt19937 (in double, then cast
// to T, so float and double models from one seed agree), so the values differ from PyTorch's RNG; N(0, 1)
// uses std::normal_distribution, whose algorithm the C++ standard leaves to the library.
//
// Templated on the scalar: float for training, double for finite-difference tests.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lumigauss/shading/sh.h"

namespace lumigauss {

inline constexpr int kEmbeddingDim = 24;  // N_a
inline constexpr int kMlpWidth = 64;      // mlp_W
inline constexpr int kEnvShOutputs = 3 * kShCount;

// The three Linear layers: 24 -> 64 -> 64 -> 27, W of each out x in.
struct MlpLayerShape {
    int out, in;
};
inline constexpr std::array<MlpLayerShape, 3> kMlpLayers{
    {{kMlpWidth, kEmbeddingDim}, {kMlpWidth, kMlpWidth}, {kEnvShOutputs, kMlpWidth}}};

// The 27 outputs <-> 9 x RGB coefficients: official `reshape(3, 9)`, so output ch * 9 + k is (k, ch).
constexpr int env_sh_output(int k, int ch) {
    return ch * kShCount + k;
}

// The parameter groups, in storage and file order.
enum class MlpGroup : int { kEmbedding = 0, kW1, kB1, kW2, kB2, kW3, kB3 };
inline constexpr int kMlpGroupCount = 7;

// Name used in files and logs ("embedding", "w1", "b1", ...).
const char* mlp_group_name(MlpGroup g);

// Everything one forward pass computed that its backward needs, plus the result.
template <typename T>
struct LightingForward {
    int image = -1;
    std::array<T, kEmbeddingDim> input{};  // the embedding row as it was at forward time
    std::array<T, kMlpWidth> h1{};         // post-ReLU; the ReLU passes gradient where h > 0
    std::array<T, kMlpWidth> h2{};
    ShCoeffs<T> sh;  // environment radiance SH L_lm of the photo
};

template <typename T>
class BasicLightingMlp {
  public:
    BasicLightingMlp() = default;
    // num_images rows in the embedding table (the official code fixes 1700 rows; we size it to the data).
    BasicLightingMlp(int num_images, std::uint32_t seed);
    // All parameters 0, for readers that fill them in (drawing the initial weights is most of the cost of
    // reading a small file).
    static BasicLightingMlp zeros(int num_images);

    int num_images() const { return num_images_; }

    LightingForward<T> forward(int image) const;
    ShCoeffs<T> env_sh(int image) const { return forward(image).sh; }

    std::vector<T>& param(MlpGroup g) { return params_[index(g)]; }
    const std::vector<T>& param(MlpGroup g) const { return params_[index(g)]; }

    // Row width of a group for row-wise optimizer operations (the embedding: 24 per image; others: 1).
    static int row_width(MlpGroup g) { return g == MlpGroup::kEmbedding ? kEmbeddingDim : 1; }
    // Number of floats a group holds for `num_images` photos.
    static std::size_t group_size(MlpGroup g, int num_images);

  private:
    static int index(MlpGroup g) { return static_cast<int>(g); }

    int num_images_ = 0;
    std::array<std::vector<T>, kMlpGroupCount> params_;
};

using LightingMlp = BasicLightingMlp<float>;

// File format (binary, little-endian), written atomically:
//   8 bytes  magic "LGLMLP01"
//   5 x int32  num_images, embedding dim (24), width (64), outputs (27), group count (7)
//   then, for each group in MlpGroup order, its float32 values (row-major, sizes as group_size()).
// Only the parameters are stored (no optimizer state).
void save_lighting_mlp(const std::string& path, const LightingMlp& mlp);
// Throws Error naming the file if it is missing, truncated, has another magic or other dimensions.
LightingMlp load_lighting_mlp(const std::string& path);

}  // namespace lumigauss
