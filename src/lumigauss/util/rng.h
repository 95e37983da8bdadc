#pragma once
// A small counter-based random generator. Every random decision is drawn from a stream keyed by
// (seed, purpose, index...), never from a shared sequential generator, so the output does not depend on the
// order in which threads run and is identical on every platform (std::*_distribution is
// implementation-defined, so we do not use it). Used by the scene generator, the model's initialisation and
// densification, and the trainer.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <type_traits>

namespace lumigauss {

// SplitMix64 finaliser: a bijective 64-bit mix with good avalanche.
inline constexpr std::uint64_t mix64(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// Combines a seed with further keys into one stream key.
inline constexpr std::uint64_t hash_keys(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0,
                                         std::uint64_t c = 0) {
    return mix64(mix64(mix64(mix64(seed) ^ a) ^ b) ^ c);
}

class Rng {
  public:
    explicit Rng(std::uint64_t key) : state_(key) {}
    // The stream of `purpose` (any enum of its caller's purposes) and its indices under `seed`.
    template <typename Purpose>
    requires std::is_enum_v<Purpose> Rng(std::uint64_t seed, Purpose purpose, std::uint64_t index = 0,
                                         std::uint64_t sub = 0)
        : state_(hash_keys(seed, static_cast<std::uint64_t>(purpose), index, sub)) {}

    std::uint64_t next_u64() {
        state_ += 0x9e3779b97f4a7c15ULL;
        return mix64(state_);
    }
    // Uniform in [0, 1) with 53 random bits.
    double uniform() { return double(next_u64() >> 11) * 0x1.0p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    // Uniform integer in [lo, hi] (inclusive); the tiny modulo bias is irrelevant here.
    int uniform_int(int lo, int hi) { return lo + int(next_u64() % std::uint64_t(hi - lo + 1)); }
    bool bernoulli(double p) { return uniform() < p; }
    // Standard normal (Box-Muller, one value per call for simplicity).
    double normal() {
        const double u1 = 1.0 - uniform();  // (0, 1]
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    }

  private:
    std::uint64_t state_;
};

}  // namespace lumigauss
