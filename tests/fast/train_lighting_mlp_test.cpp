// The per-photo lighting MLP: shapes and initialisation as the official code, the output reshape, every
// gradient against central differences in double, and the file round trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>

#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/train/lighting_mlp_gradients.h"
#include "lumigauss/util/error.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

constexpr MlpGroup kAllGroups[kMlpGroupCount] = {MlpGroup::kEmbedding, MlpGroup::kW1, MlpGroup::kB1,
                                                 MlpGroup::kW2,        MlpGroup::kB2, MlpGroup::kW3,
                                                 MlpGroup::kB3};

ShCoeffs<double> random_sh(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    ShCoeffs<double> g;
    for (auto& c : g.c) c = {u(rng), u(rng), u(rng)};
    return g;
}

// L = <G, SH(image)>.
double loss(const BasicLightingMlp<double>& mlp, int image, const ShCoeffs<double>& g) {
    const ShCoeffs<double> sh = mlp.env_sh(image);
    double l = 0;
    for (int k = 0; k < kShCount; ++k) l += dot(g.c[k], sh.c[k]);
    return l;
}

TEST(TrainMlp, ShapesMatchOfficial) {
    const LightingMlp mlp(5, 1);
    EXPECT_EQ(mlp.param(MlpGroup::kEmbedding).size(), 5u * 24u);
    EXPECT_EQ(mlp.param(MlpGroup::kW1).size(), 64u * 24u);
    EXPECT_EQ(mlp.param(MlpGroup::kB1).size(), 64u);
    EXPECT_EQ(mlp.param(MlpGroup::kW2).size(), 64u * 64u);
    EXPECT_EQ(mlp.param(MlpGroup::kB2).size(), 64u);
    EXPECT_EQ(mlp.param(MlpGroup::kW3).size(), 27u * 64u);
    EXPECT_EQ(mlp.param(MlpGroup::kB3).size(), 27u);
    const LightingMlpGradients grads(mlp);
    for (MlpGroup g : kAllGroups) EXPECT_EQ(grads[g].size(), mlp.param(g).size());
    EXPECT_EQ(LightingMlp::row_width(MlpGroup::kEmbedding), 24);
    EXPECT_EQ(LightingMlp::row_width(MlpGroup::kW2), 1);
}

TEST(TrainMlp, InitialisationFollowsPytorchDistributions) {
    const LightingMlp mlp(200, 7);
    // nn.Linear: U(-1/sqrt(fan_in), 1/sqrt(fan_in)) for weights and biases.
    const auto within = [&](MlpGroup g, double fan_in) {
        const double bound = 1.0 / std::sqrt(fan_in);
        double max_abs = 0;
        for (float v : mlp.param(g)) max_abs = std::max(max_abs, std::abs(double(v)));
        EXPECT_LE(max_abs, bound) << mlp_group_name(g);
        EXPECT_GT(max_abs, 0.9 * bound) << mlp_group_name(g);  // fills the range, not a smaller one
    };
    within(MlpGroup::kW1, 24), within(MlpGroup::kB1, 24);
    within(MlpGroup::kW2, 64), within(MlpGroup::kB2, 64);
    within(MlpGroup::kW3, 64), within(MlpGroup::kB3, 64);
    // nn.Embedding: N(0, 1).
    const auto& e = mlp.param(MlpGroup::kEmbedding);
    double sum = 0, sum2 = 0;
    for (float v : e) sum += v, sum2 += double(v) * v;
    const double mean = sum / double(e.size()), var = sum2 / double(e.size()) - mean * mean;
    EXPECT_NEAR(mean, 0.0, 0.05);
    EXPECT_NEAR(std::sqrt(var), 1.0, 0.05);
    // Fresh gradients are zero.
    const LightingMlpGradients grads(mlp);
    for (MlpGroup g : kAllGroups)
        for (float v : grads[g]) ASSERT_EQ(v, 0.0f);
}

TEST(TrainMlp, SeedIsDeterministicAndFloatMatchesDouble) {
    const LightingMlp a(3, 42), b(3, 42), c(3, 43);
    const BasicLightingMlp<double> d(3, 42);
    EXPECT_EQ(a.param(MlpGroup::kW2), b.param(MlpGroup::kW2));
    EXPECT_NE(a.param(MlpGroup::kW2), c.param(MlpGroup::kW2));
    for (MlpGroup g : kAllGroups)
        for (std::size_t i = 0; i < a.param(g).size(); ++i)
            ASSERT_EQ(a.param(g)[i], static_cast<float>(d.param(g)[i])) << mlp_group_name(g);
}

TEST(TrainMlp, OutputReshapeIsChannelMajorAsOfficial) {
    // Official `outputs.reshape(3, 9)`: output ch * 9 + k is coefficient k of channel ch.
    LightingMlp mlp(1, 3);
    auto& w3 = mlp.param(MlpGroup::kW3);
    std::fill(w3.begin(), w3.end(), 0.0f);
    auto& b3 = mlp.param(MlpGroup::kB3);
    for (int o = 0; o < kEnvShOutputs; ++o) b3[o] = float(o);
    const ShCoeffs<float> sh = mlp.env_sh(0);
    for (int k = 0; k < kShCount; ++k)
        for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(sh.c[k][ch], float(ch * 9 + k)) << k << " " << ch;
}

TEST(TrainMlp, ForwardMatchesPlainFormula) {
    // An independent evaluation of relu(W1 e + b1) etc. for one output, to catch transposed weights.
    const BasicLightingMlp<double> mlp(2, 5);
    const auto& p = [&](MlpGroup g) -> const std::vector<double>& { return mlp.param(g); };
    const double* e = &p(MlpGroup::kEmbedding)[24];
    double h1[64], h2[64];
    for (int o = 0; o < 64; ++o) {
        double a = p(MlpGroup::kB1)[o];
        for (int i = 0; i < 24; ++i) a += p(MlpGroup::kW1)[o * 24 + i] * e[i];
        h1[o] = std::max(a, 0.0);
    }
    for (int o = 0; o < 64; ++o) {
        double a = p(MlpGroup::kB2)[o];
        for (int i = 0; i < 64; ++i) a += p(MlpGroup::kW2)[o * 64 + i] * h1[i];
        h2[o] = std::max(a, 0.0);
    }
    const ShCoeffs<double> sh = mlp.env_sh(1);
    for (int o = 0; o < 27; ++o) {
        double a = p(MlpGroup::kB3)[o];
        for (int i = 0; i < 64; ++i) a += p(MlpGroup::kW3)[o * 64 + i] * h2[i];
        EXPECT_NEAR(sh.c[o % 9][o / 9], a, 1e-12);
    }
}

TEST(TrainMlp, GradientsMatchFiniteDifferences) {
    std::mt19937 rng(11);
    BasicLightingMlp<double> mlp(3, 17);
    const int image = 1;
    const ShCoeffs<double> g = random_sh(rng);
    BasicLightingMlpGradients<double> grads(mlp);
    grads.backward(mlp, mlp.forward(image), g);

    const double h = 1e-6;
    int active = 0;
    for (double v : mlp.forward(image).h1) active += v > 0;
    ASSERT_GT(active, 8);  // enough units pass the ReLU for the check to mean something
    for (MlpGroup grp : kAllGroups) {
        auto& p = mlp.param(grp);
        const auto& grad = grads[grp];
        double max_err = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            const double saved = p[i];
            p[i] = saved + h;
            const double lp = loss(mlp, image, g);
            p[i] = saved - h;
            const double lm = loss(mlp, image, g);
            p[i] = saved;
            const double fd = (lp - lm) / (2 * h);
            max_err = std::max(max_err, std::abs(fd - grad[i]) / (1e-6 + std::abs(fd)));
            ASSERT_NEAR(grad[i], fd, 1e-6 + 1e-6 * std::abs(fd)) << mlp_group_name(grp) << " [" << i << "]";
        }
        SCOPED_TRACE(mlp_group_name(grp));
        EXPECT_LT(max_err, 1e-4);
    }
    // Only the used embedding row gets gradient (the table's gradient is dense, zeros elsewhere).
    const auto& ge = grads[MlpGroup::kEmbedding];
    for (int i = 0; i < 24; ++i) {
        EXPECT_EQ(ge[i], 0.0);
        EXPECT_EQ(ge[2 * 24 + i], 0.0);
    }
}

TEST(TrainMlp, BackwardAccumulatesUntilReset) {
    std::mt19937 rng(2);
    BasicLightingMlp<double> mlp(2, 9);
    const ShCoeffs<double> g = random_sh(rng);
    const auto fwd = mlp.forward(0);
    BasicLightingMlpGradients<double> grads(mlp);
    grads.backward(mlp, fwd, g);
    const std::vector<double> once = grads[MlpGroup::kW1];
    grads.backward(mlp, fwd, g);
    for (std::size_t i = 0; i < once.size(); ++i) ASSERT_DOUBLE_EQ(grads[MlpGroup::kW1][i], 2 * once[i]);
    grads.reset(mlp);
    for (MlpGroup grp : kAllGroups)
        for (double v : grads[grp]) ASSERT_EQ(v, 0.0);
    // Gradients shaped for another MLP are refused rather than written out of bounds.
    const BasicLightingMlp<double> bigger(5, 9);
    EXPECT_THROW(grads.backward(bigger, bigger.forward(4), g), Error);
}

TEST(TrainMlp, ForwardRejectsBadImageIndex) {
    const LightingMlp mlp(2, 1);
    EXPECT_THROW((void)mlp.forward(2), Error);
    EXPECT_THROW((void)mlp.forward(-1), Error);
}

// The readers' starting point: the shape of a drawn model, every value 0.
TEST(TrainMlp, ZerosHasTheShapeOfADrawnModel) {
    const LightingMlp drawn(5, 3), zeros = LightingMlp::zeros(5);
    ASSERT_EQ(zeros.num_images(), 5);
    for (MlpGroup g : kAllGroups) {
        EXPECT_EQ(zeros.param(g).size(), drawn.param(g).size()) << mlp_group_name(g);
        EXPECT_TRUE(
            std::all_of(zeros.param(g).begin(), zeros.param(g).end(), [](float v) { return v == 0; }));
    }
    EXPECT_THROW((void)LightingMlp::zeros(-1), Error);
}

TEST(TrainMlp, SaveLoadRoundTrip) {
    lumigauss::testing::TempDir dir("TrainMlp_SaveLoad");
    const LightingMlp mlp(4, 21);
    const std::string path = dir / "lighting.bin";
    save_lighting_mlp(path, mlp);
    const LightingMlp back = load_lighting_mlp(path);
    ASSERT_EQ(back.num_images(), 4);
    for (MlpGroup g : kAllGroups) EXPECT_EQ(back.param(g), mlp.param(g)) << mlp_group_name(g);
    const ShCoeffs<float> a = mlp.env_sh(3), b = back.env_sh(3);
    for (int k = 0; k < kShCount; ++k)
        for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(a.c[k][ch], b.c[k][ch]);
}

TEST(TrainMlp, LoadRejectsBadFiles) {
    lumigauss::testing::TempDir dir("TrainMlp_LoadBad");
    EXPECT_THROW(load_lighting_mlp(dir / "missing.bin"), Error);

    const std::string path = dir / "lighting.bin";
    save_lighting_mlp(path, LightingMlp(2, 1));
    std::string bytes;
    {
        std::ifstream in(path, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    const auto write = [&](const std::string& name, const std::string& content) {
        std::ofstream(dir / name, std::ios::binary) << content;
        return dir / name;
    };
    EXPECT_THROW(load_lighting_mlp(write("truncated.bin", bytes.substr(0, bytes.size() - 4))), Error);
    EXPECT_THROW(load_lighting_mlp(write("trailing.bin", bytes + "x")), Error);
    // A photo count of 2^25 in a file of a few kilobytes allocated 4.8 GB (found by fuzz_lighting_files): the
    // count is checked against the file's size first.
    std::string many = bytes;
    const std::int32_t photos = 1 << 25;
    std::memcpy(many.data() + 8, &photos, sizeof photos);
    try {
        load_lighting_mlp(write("many.bin", many));
        ADD_FAILURE() << "a photo count the file cannot hold was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("wrong photo count"), std::string::npos) << e.what();
    }
    std::string bad_magic = bytes;
    bad_magic[0] = 'X';
    EXPECT_THROW(load_lighting_mlp(write("magic.bin", bad_magic)), Error);
    try {
        load_lighting_mlp(write("magic2.bin", bad_magic));
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("magic2.bin"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace lumigauss
