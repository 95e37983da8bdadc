#include "lumigauss/model/lighting_mlp.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

static_assert(std::endian::native == std::endian::little, "the MLP file format is written as little-endian");

constexpr char kMagic[8] = {'L', 'G', 'L', 'M', 'L', 'P', '0', '1'};

// y = W x + b with W row-major (out x in), as nn.Linear.
template <typename T>
void linear(const std::vector<T>& w, const std::vector<T>& b, MlpLayerShape s, const T* x, T* y) {
    for (int o = 0; o < s.out; ++o) {
        T acc = b[o];
        const T* row = &w[static_cast<std::size_t>(o) * s.in];
        for (int i = 0; i < s.in; ++i) acc += row[i] * x[i];
        y[o] = acc;
    }
}

template <typename T, std::size_t N>
void relu(std::array<T, N>& v) {
    for (T& x : v) x = x > T(0) ? x : T(0);
}

void read_exact(std::ifstream& in, const std::string& path, void* dst, std::size_t bytes) {
    in.read(static_cast<char*>(dst), static_cast<std::streamsize>(bytes));
    if (!in) fail_in_file(path, "truncated lighting MLP file");
}

}  // namespace

const char* mlp_group_name(MlpGroup g) {
    static constexpr const char* kNames[kMlpGroupCount] = {"embedding", "w1", "b1", "w2", "b2", "w3", "b3"};
    return kNames[static_cast<int>(g)];
}

template <typename T>
std::size_t BasicLightingMlp<T>::group_size(MlpGroup g, int num_images) {
    if (g == MlpGroup::kEmbedding) return static_cast<std::size_t>(num_images) * kEmbeddingDim;
    const int layer = (static_cast<int>(g) - 1) / 2;
    const bool is_weight = (static_cast<int>(g) - 1) % 2 == 0;
    const MlpLayerShape s = kMlpLayers[layer];
    return static_cast<std::size_t>(is_weight ? s.out * s.in : s.out);
}

template <typename T>
BasicLightingMlp<T>::BasicLightingMlp(int num_images, std::uint32_t seed) : num_images_(num_images) {
    if (num_images < 0) throw Error("lighting MLP: negative number of images");
    std::mt19937 rng(seed);
    // Draw in double and cast, so float and double models from one seed hold the same values.
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int gi = 0; gi < kMlpGroupCount; ++gi) {
        const auto g = static_cast<MlpGroup>(gi);
        params_[gi].resize(group_size(g, num_images));
        if (g == MlpGroup::kEmbedding) {
            for (T& v : params_[gi]) v = static_cast<T>(normal(rng));
            continue;
        }
        // nn.Linear.reset_parameters: kaiming_uniform(a = sqrt 5) for W and U(+-1/sqrt(fan_in)) for b, which
        // are both U(-1/sqrt(fan_in), 1/sqrt(fan_in)).
        const double bound = 1.0 / std::sqrt(static_cast<double>(kMlpLayers[(gi - 1) / 2].in));
        std::uniform_real_distribution<double> uniform(-bound, bound);
        for (T& v : params_[gi]) v = static_cast<T>(uniform(rng));
    }
}

template <typename T>
BasicLightingMlp<T> BasicLightingMlp<T>::zeros(int num_images) {
    if (num_images < 0) throw Error("lighting MLP: negative number of images");
    BasicLightingMlp mlp;
    mlp.num_images_ = num_images;
    for (int gi = 0; gi < kMlpGroupCount; ++gi)
        mlp.params_[gi].assign(group_size(static_cast<MlpGroup>(gi), num_images), T(0));
    return mlp;
}

template <typename T>
LightingForward<T> BasicLightingMlp<T>::forward(int image) const {
    if (image < 0 || image >= num_images_)
        throw Error("lighting MLP: image index " + std::to_string(image) + " out of range [0, " +
                    std::to_string(num_images_) + ")");
    LightingForward<T> f;
    f.image = image;
    const T* row = &param(MlpGroup::kEmbedding)[static_cast<std::size_t>(image) * kEmbeddingDim];
    std::copy(row, row + kEmbeddingDim, f.input.begin());

    linear(param(MlpGroup::kW1), param(MlpGroup::kB1), kMlpLayers[0], f.input.data(), f.h1.data());
    relu(f.h1);
    linear(param(MlpGroup::kW2), param(MlpGroup::kB2), kMlpLayers[1], f.h1.data(), f.h2.data());
    relu(f.h2);
    std::array<T, kEnvShOutputs> out{};
    linear(param(MlpGroup::kW3), param(MlpGroup::kB3), kMlpLayers[2], f.h2.data(), out.data());

    for (int k = 0; k < kShCount; ++k)
        for (int ch = 0; ch < 3; ++ch) f.sh.c[k][ch] = out[env_sh_output(k, ch)];
    return f;
}

template class BasicLightingMlp<float>;
template class BasicLightingMlp<double>;

void save_lighting_mlp(const std::string& path, const LightingMlp& mlp) {
    std::string bytes(kMagic, sizeof kMagic);
    auto put = [&bytes](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); };
    const std::int32_t header[5] = {mlp.num_images(), kEmbeddingDim, kMlpWidth, kEnvShOutputs,
                                    kMlpGroupCount};
    put(header, sizeof header);
    for (int gi = 0; gi < kMlpGroupCount; ++gi) {
        const auto& v = mlp.param(static_cast<MlpGroup>(gi));
        put(v.data(), v.size() * sizeof(float));
    }
    write_file_atomically(path, bytes);
}

LightingMlp load_lighting_mlp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail_in_file(path, "cannot open lighting MLP file");
    char magic[sizeof kMagic];
    read_exact(in, path, magic, sizeof magic);
    if (std::memcmp(magic, kMagic, sizeof kMagic) != 0)
        fail_in_file(path, "not a lighting MLP file (bad magic)");
    std::int32_t header[5];
    read_exact(in, path, header, sizeof header);
    if (header[0] < 0 || header[1] != kEmbeddingDim || header[2] != kMlpWidth || header[3] != kEnvShOutputs ||
        header[4] != kMlpGroupCount)
        fail_in_file(path, "lighting MLP dimensions differ from 24-64-64-27 (or a negative image count)");

    // The photo count sizes the embedding: check it against the file before allocating for it.
    std::size_t expected_floats = std::size_t(header[0]) * kEmbeddingDim;
    for (int gi = 0; gi < kMlpGroupCount; ++gi)
        expected_floats += LightingMlp::group_size(static_cast<MlpGroup>(gi), 0);
    const auto file_bytes = std::filesystem::file_size(path);
    const std::size_t header_bytes = sizeof magic + sizeof header;
    if (file_bytes != header_bytes + expected_floats * sizeof(float))
        fail_in_file(path, "holds " + std::to_string(file_bytes) + " bytes, but a lighting MLP of " +
                               std::to_string(header[0]) + " photos takes " +
                               std::to_string(header_bytes + expected_floats * sizeof(float)) +
                               " (truncated, or a wrong photo count)");
    LightingMlp mlp = LightingMlp::zeros(header[0]);
    for (int gi = 0; gi < kMlpGroupCount; ++gi) {
        auto& v = mlp.param(static_cast<MlpGroup>(gi));
        read_exact(in, path, v.data(), v.size() * sizeof(float));
    }
    if (in.peek() != std::ifstream::traits_type::eof())
        fail_in_file(path, "trailing bytes after lighting MLP");
    return mlp;
}

}  // namespace lumigauss
