#include "lumigauss/train/physical_losses.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "lumigauss/math/hd.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/multiversion.h"
#include "lumigauss/util/rng.h"

namespace lumigauss {
namespace {

constexpr std::size_t kChunk = 4096;
// Stream purposes of the training generator (distinct from each other; the seed is the run's).
constexpr std::uint64_t kTransferDirections = 0x7472616e73ULL;  // "trans"
constexpr std::uint64_t kEnvDirections = 0x656e76ULL;           // "env"

template <typename T>
void sample_directions(Rng& rng, int count, Vec3<T>* out) {
    for (int s = 0; s < count; ++s) {
        const Vec3<T> u{T(rng.uniform(-1, 1)), T(rng.uniform(-1, 1)), T(rng.uniform(-1, 1))};
        out[s] = cube_normalized_direction(u);
    }
}

// The transfer losses run 25 directions for every surfel at every iteration (2.5 M samples for 100k
// surfels), so they are written for SIMD: kLanes surfels side by side, one lane each, with a 32-bit
// counter hash per random number (vectorisable, unlike a sequential generator).
constexpr int kLanes = 16;

LG_HD_INLINE std::uint32_t hash32(std::uint32_t x) {  // "lowbias32" finaliser (C. Wellons)
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

// Uniform in [-1, 1) from the random number `index` of a surfel's stream.
LG_HD_INLINE float uniform_pm1(std::uint32_t key_lo, std::uint32_t key_hi, std::uint32_t index) {
    const std::uint32_t h = hash32((key_lo + index * 0x9e3779b9U) ^ key_hi);
    return float(h >> 8) * 0x1.0p-23f - 1.0f;
}

// What one surfel's samples contribute: the loss sums, and the four moments whose combination with the
// global scales gives its gradient (the scales depend on counts over all surfels, so the gradient can
// only be formed after the reduction; keeping these moments avoids a second pass over the samples):
//   g_T = 2 (s_cons A + s_below B + s_above C + s_shadow D), with
//   A = sum (t - c) Y,  B = sum_{t<0} t Y,  C = sum_{t>1} (t - 1) Y,  D = sum_{t>c} (t - c) Y.
constexpr int kMoments = 4 * kShCount;

struct LaneBatch {
    float transfer[kShCount][kLanes]{};
    float nx[kLanes]{}, ny[kLanes]{}, nz[kLanes]{};
    std::uint32_t key_lo[kLanes]{}, key_hi[kLanes]{};
    float below_sq[kLanes]{}, above_sq[kLanes]{}, cons_sq[kLanes]{}, shadow_sq[kLanes]{};
    float below_n[kLanes]{}, above_n[kLanes]{};
    float moment[kMoments][kLanes]{};
};

// Inlined into each per-instruction-set wrapper below; a plain inline function would be compiled once, for
// the baseline, and the wrappers would gain nothing.
template <bool kWithMoments>
LG_HD_INLINE void run_samples_impl(LaneBatch& b, int samples) {
    for (int s = 0; s < samples; ++s) {
        const auto i0 = std::uint32_t(3 * s);
#pragma omp simd
        for (int l = 0; l < kLanes; ++l) {
            const float ux = uniform_pm1(b.key_lo[l], b.key_hi[l], i0);
            const float uy = uniform_pm1(b.key_lo[l], b.key_hi[l], i0 + 1);
            const float uz = uniform_pm1(b.key_lo[l], b.key_hi[l], i0 + 2);
            // 4.2: u / (|u| + 1e-7)
            const float inv =
                1.0f / (std::sqrt(ux * ux + uy * uy + uz * uz) + float(surfel_const::kDirectionEps));
            const float x = ux * inv, y = uy * inv, z = uz * inv;
            // sh_basis (shading/sh.h) spelled out in scalars: a local array in this loop defeats GCC's
            // vectoriser. TrainPhysicalLosses checks the results against known answers and the
            // expectation over cube-normalised directions.
            using namespace sh_const;
            const float basis[kShCount] = {float(kY00),
                                           float(kY1) * y,
                                           float(kY1) * z,
                                           float(kY1) * x,
                                           float(kY2) * x * y,
                                           float(kY2) * y * z,
                                           float(kY20) * (3 * z * z - 1),
                                           float(kY2) * x * z,
                                           float(kY22) * (x * x - y * y)};
            float t = 0;
#pragma GCC unroll 9
            for (int k = 0; k < kShCount; ++k) t += b.transfer[k][l] * basis[k];
            const float cosine = b.nx[l] * x + b.ny[l] * y + b.nz[l] * z;
            const float c = cosine > 0 ? cosine : 0.0f;
            const float diff = t - c;
            const float below = t < 0 ? t : 0.0f;
            const float above = t > 1 ? t - 1 : 0.0f;
            const float shadow = diff > 0 ? diff : 0.0f;
            b.below_sq[l] += below * below;
            b.above_sq[l] += above * above;
            b.cons_sq[l] += diff * diff;
            b.shadow_sq[l] += shadow * shadow;
            b.below_n[l] += t < 0 ? 1.0f : 0.0f;
            b.above_n[l] += t > 1 ? 1.0f : 0.0f;
            if constexpr (kWithMoments)
#pragma GCC unroll 9
                for (int k = 0; k < kShCount; ++k) {
                    b.moment[k][l] += diff * basis[k];
                    b.moment[kShCount + k][l] += below * basis[k];
                    b.moment[2 * kShCount + k][l] += above * basis[k];
                    b.moment[3 * kShCount + k][l] += shadow * basis[k];
                }
        }
    }
}

// The sampling loop compiled for baseline x86-64, AVX2 and AVX-512 (util/multiversion.h).
LG_MULTIVERSION void run_samples_with_moments(LaneBatch& b, int samples) {
    run_samples_impl<true>(b, samples);
}
LG_MULTIVERSION void run_samples_values_only(LaneBatch& b, int samples) {
    run_samples_impl<false>(b, samples);
}

}  // namespace

TransferLossResult model_transfer_losses(GaussianModel& model, const ViewNormals& normals, int samples,
                                         std::uint64_t seed, std::int64_t iteration,
                                         const TransferLossWeights<double>& weights, bool backward) {
    const std::size_t n = model.size();
    if (normals.normal.size() != n || normals.positive_side.size() != n)
        throw Error("model_transfer_losses: normals were computed for another model size");
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    const auto& pos = model.param(ModelParam::TransferPositive);
    const auto& neg = model.param(ModelParam::TransferNegative);
    const bool any_weight = weights.range01 != 0 || weights.consistency != 0 || weights.shadow != 0;
    const bool moments = backward && any_weight;
    std::vector<float> surfel_moments(moments ? n * kMoments : 0);
    std::vector<TransferLossSums<double>> partial(chunks);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t chunk = r.begin(); chunk < r.end(); ++chunk) {
                const std::size_t end = std::min(n, (chunk + 1) * kChunk);
                for (std::size_t first = chunk * kChunk; first < end; first += kLanes) {
                    const int lanes = int(std::min<std::size_t>(kLanes, end - first));
                    LaneBatch b;  // padding lanes keep T = 0 and n = 0: every sample then adds exactly 0
                    for (int l = 0; l < lanes; ++l) {
                        const std::size_t i = first + std::size_t(l);
                        const auto& t = normals.positive_side[i] ? pos : neg;
                        for (int k = 0; k < kShCount; ++k)
                            b.transfer[k][l] = t[i * kTransferStored + std::size_t(3 * k)];
                        b.nx[l] = normals.normal[i].x, b.ny[l] = normals.normal[i].y,
                        b.nz[l] = normals.normal[i].z;
                        const std::uint64_t key =
                            hash_keys(seed, kTransferDirections, std::uint64_t(iteration), i);
                        b.key_lo[l] = std::uint32_t(key), b.key_hi[l] = std::uint32_t(key >> 32);
                    }
                    if (moments)
                        run_samples_with_moments(b, samples);
                    else
                        run_samples_values_only(b, samples);
                    TransferLossSums<double>& sum = partial[chunk];
                    for (int l = 0; l < lanes; ++l) {
                        sum.below_sq += b.below_sq[l], sum.above_sq += b.above_sq[l];
                        sum.consistency_sq += b.cons_sq[l], sum.shadow_sq += b.shadow_sq[l];
                        sum.below_count += (long long)b.below_n[l],
                            sum.above_count += (long long)b.above_n[l];
                        if (moments)
                            for (int k = 0; k < kMoments; ++k)
                                surfel_moments[(first + std::size_t(l)) * kMoments + std::size_t(k)] =
                                    b.moment[k][l];
                    }
                    sum.samples += (long long)lanes * samples;
                }
            }
        });
    TransferLossSums<double> total;
    for (const auto& p : partial) total += p;

    TransferLossResult result;
    result.losses = transfer_losses(total);
    result.weighted = weighted_transfer_loss(result.losses, weights);
    if (!moments) return result;

    const TransferLossScales<double> sc = transfer_loss_scales(total, weights);
    const float s[4] = {float(2 * sc.consistency_sq), float(2 * sc.below_sq), float(2 * sc.above_sq),
                        float(2 * sc.shadow_sq)};
    std::span<float> g_pos = model.grad(ModelParam::TransferPositive);
    std::span<float> g_neg = model.grad(ModelParam::TransferNegative);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const float* m = &surfel_moments[i * kMoments];
            std::span<float> dst = normals.positive_side[i] ? g_pos : g_neg;
            for (int k = 0; k < kShCount; ++k)
                dst[i * kTransferStored + std::size_t(3 * k)] += s[0] * m[k] + s[1] * m[kShCount + k] +
                                                                 s[2] * m[2 * kShCount + k] +
                                                                 s[3] * m[3 * kShCount + k];
        }
    });
    return result;
}

double env_nonnegativity_loss(const ShCoeffs<float>& env, int samples, std::uint64_t seed,
                              std::int64_t iteration, double weight, ShCoeffs<float>& g_env) {
    Rng rng(hash_keys(seed, kEnvDirections, std::uint64_t(iteration)));
    std::vector<Vec3<double>> dirs(std::size_t(std::max(samples, 0)));
    sample_directions(rng, samples, dirs.data());
    const ShCoeffs<double> sh = env.cast<double>();
    // penalize_outside_range(v, 0, inf): mean of v^2 over the negative values only (all channels together).
    double sum = 0;
    long long count = 0;
    for (const auto& d : dirs) {
        const Vec3<double> v = eval_sh(sh, d);
        for (int c = 0; c < 3; ++c)
            if (!(v[c] >= 0)) sum += v[c] * v[c], ++count;  // NaN counts, so the loss reports it
    }
    if (count == 0) return 0.0;
    const double loss = sum / double(count);
    if (weight == 0) return loss;
    ShCoeffs<double> g{};
    for (const auto& d : dirs) {
        const Vec3<double> v = eval_sh(sh, d);
        Vec3<double> gv{};
        for (int c = 0; c < 3; ++c) gv[c] = v[c] < 0 ? weight * 2 * v[c] / double(count) : 0.0;
        eval_sh_vjp_coeffs(d, gv, g);
    }
    for (int k = 0; k < kShCount; ++k) g_env.c[k] = g_env.c[k] + g.c[k].cast<float>();
    return loss;
}

}  // namespace lumigauss
