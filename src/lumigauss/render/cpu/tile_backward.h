#pragma once
// Backward of one 16x16 tile (internal to the CPU backend), block by block like the forward
// (tile_blocks.h): each block walks back to front the surfels the forward composited into it, un-blending
// them (pixel_blend.h) with the pixels' state in registers. (The others would have alpha 0 in every pixel
// of the block, which changes nothing.) The walk records what each entry received, and a second pass over
// the records turns it into the surfel's kernel gradients. The surfel's gradients over the block's eight
// lanes are summed at once (lane_sums) into its per-tile sums, which the tile finally writes into the
// surfel's (surfel, tile) slot: every slot is written by exactly one tile, in a fixed order, so the result
// does not depend on threads.
#include <algorithm>
#include <cstdint>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/streaming_store.h"
#include "lumigauss/render/cpu/tile_forward.h"
#include "lumigauss/render/gradient_slot.h"

namespace lumigauss::cpu {

// Layout of one (surfel, tile) gradient slot (gradient_slot.h), padded to whole packs.
struct SlotLayout : raster::GradSlot {
    // Slots are whole packs (the padding holds zeros), so that they are summed and copied as packs.
    static constexpr int stride(int channels) { return (values(channels) + kLanes - 1) / kLanes * kLanes; }
    // The slots' spacing in the gradient buffer: whole cache lines (counted in float: one line in float, two
    // in double), so that the tiles write them past the caches in full lines (render_tile_backward).
    static constexpr int kLineValues = int(kCacheLineBytes / sizeof(float));
    static constexpr int line_stride(int channels) {
        return (values(channels) + kLineValues - 1) / kLineValues * kLineValues;
    }
    static constexpr std::size_t kAlign = kCacheLineBytes;  // bytes: where the buffer starts
};

template <typename T>
T grad_at(const std::vector<T>& g, std::size_t i) {
    return g.empty() ? T(0) : g[i];
}

// The backward walk's starting state of a block: what the forward left and the incoming gradients.
// Lanes off the image keep contributors = 0 and zero gradients, so they never take part. The lanes are
// gathered into plain arrays and loaded as whole packs: written lane by lane into the packs themselves,
// GCC kept some of them in two 16-byte halves and re-assembled them in every iteration of the walk, a
// store-forwarding stall per entry with AVX2.
template <typename T, int C>
LG_ALWAYS_INLINE void load_block(raster::BlendPixelBackward<Pack8<T>, C>& s, int x0, int y0,
                                 const raster::PixelRect& tr, int channels, const RasterState<T>& st,
                                 const RasterImageGrads<T>& g) {
    using I = typename Int8<T>::I;
    const int width = st.view.width;
    alignas(64) T trans[kLanes], bg_term[kLanes] = {}, g_color[C][kLanes] = {}, g_normal[3][kLanes] = {},
                                 g_depth[kLanes] = {}, g_alpha[kLanes] = {}, g_dist[kLanes] = {},
                                 g_median[kLanes] = {}, m1[kLanes] = {}, m2[kLanes] = {};
    alignas(64) I contributors[kLanes] = {}, median_entry[kLanes];
    for (int i = 0; i < kLanes; ++i) {
        trans[i] = T(1);
        median_entry[i] = -1;
        const int x = x0 + i % kBlockWidth, y = y0 + i / kBlockWidth;
        if (x > tr.x1 || y > tr.y1) continue;
        const std::size_t pix = std::size_t(y) * width + x;
        const T t_final = st.final_transmittance[pix];
        trans[i] = t_final;
        T dot_bg = 0;
        for (int c = 0; c < channels; ++c) {
            const T gc = grad_at(g.color, pix * channels + c);
            g_color[c][i] = gc;
            dot_bg += (st.background.empty() ? T(0) : st.background[c]) * gc;
        }
        bg_term[i] = t_final * dot_bg;
        for (int k = 0; k < 3; ++k) g_normal[k][i] = grad_at(g.normal, pix * 3 + k);
        g_depth[i] = grad_at(g.depth, pix);
        g_alpha[i] = grad_at(g.alpha, pix);
        g_dist[i] = grad_at(g.distortion, pix);
        g_median[i] = grad_at(g.median_depth, pix);
        m1[i] = st.m1[pix];
        m2[i] = st.m2[pix];
        contributors[i] = I(st.contributors[pix]);
        median_entry[i] = st.median_entry[pix];
    }
    s.trans = load_pack(trans);
    s.a_total = Pack8<T>(T(1)) - s.trans;
    s.bg_term = load_pack(bg_term);
    for (int c = 0; c < C; ++c) s.g_color[c] = load_pack(g_color[c]);
    for (int k = 0; k < 3; ++k) s.g_normal[k] = load_pack(g_normal[k]);
    s.g_depth = load_pack(g_depth);
    s.g_alpha = load_pack(g_alpha);
    s.g_dist = load_pack(g_dist);
    s.g_median = load_pack(g_median);
    s.m1 = load_pack(m1);
    s.m2 = load_pack(m2);
    s.contributors = load_lanes<T>(contributors);
    s.median_entry = load_lanes<T>(median_entry);
}

// Adds the lane sums of one surfel's per-lane gradients `q` (kPadded packs, in SlotLayout order) to its
// per-tile sums.
template <int kPadded, typename T>
LG_ALWAYS_INLINE void add_lane_sums(const Pack8<T>* q, T* sums) {
    for (int j = 0; j < kPadded; j += kLanes) store_pack(sums + j, load_pack(sums + j) + lane_sums(q + j));
}

// What a block's loops hand on about one entry (per block lane): the kernel loops evaluate straight into
// the record, the walk adds what the entry received, the gradient pass reads it all.
template <typename P>
struct UnblendedSample {
    // The kernel sample, with two fields changed for the walk: alpha is 0 where the forward did not
    // composite the pair, and screen_branch is also set there (the gradient pass reads neither alpha nor,
    // where g_alpha = g_z = 0, the branch's values).
    raster::SplatSample<P> smp;
    raster::BlendSampleGrad<P> grad;
    std::uint32_t k;  // the entry's place in the tile's list
};
// Records per chunk of a block's loops: 16 records are 6 KB in float, read back from L1 by each loop.
// (Chunks of 8 and 32 measured alike: backward tiles 32.4 and 32.6 ms against 31.3, fastest of 5 rounds.)
inline constexpr std::uint32_t kUnblendChunk = 16;

template <typename T, int C>
LG_ALWAYS_INLINE void render_tile_backward(int tile, int channels, const RasterState<T>& st,
                                           const RasterImageGrads<T>& g, T* slots, TileScratch<T>& scratch) {
    using P = Pack8<T>;
    using I = Int8<T>;
    using Unblended = UnblendedSample<P>;
    constexpr int kPadded = SlotLayout::stride(C);
    const int stride = SlotLayout::stride(channels);  // kPadded, but for the general path
    const raster::PixelRect tr = tile_pixels(tile, st.tiles_x, st.view.width, st.view.height);
    const std::uint32_t begin = st.tile_start[tile], count = st.tile_start[tile + 1] - begin;
    scratch.grads.assign(std::size_t(count) * kPadded, T(0));
    const std::vector<std::uint32_t>& kept = st.block_entries[std::size_t(tile)];
    const std::uint32_t* const kept_start = &st.block_start[std::size_t(tile) * (kTileBlocks + 1)];

    Unblended records[kUnblendChunk];  // here, not per block: its members' initialisers clear it
    for (int b = 0; b < kTileBlocks; ++b) {
        const std::uint32_t first = kept_start[b], length = kept_start[b + 1] - first;
        if (length == 0) continue;
        const int x0 = block_x0(tr, b), y0 = block_y0(tr, b);
        raster::BlendPixelBackward<P, C> s{};
        load_block(s, x0, y0, tr, channels, st, g);
        const I px = block_lane_x<T>() + I(x0), py = block_lane_y<T>() + I(y0);
        const P cx = pixel_centres(px), cy = pixel_centres(py);
        // Loops over chunks of the block's list. The first two evaluate the entries' kernels, in two
        // halves (the hit up to rho, then the exponential and alpha), with no chain between entries, so
        // that the processor overlaps consecutive entries' long chains (as in the forward:
        // tile_forward.h). The walk (back to front) then un-blends them: its only chain from entry to
        // entry is the transmittance and the "behind" dot product. It records what the gradient pass
        // needs; that pass (splat_grad_terms and the lane sums, most of the work) has no chain between
        // entries at all either. (One loop doing all of it was latency-bound: an iteration filled the
        // reorder window.) As in the forward, no lane tests the entry's pixel box.
        const auto walked = [&](std::uint32_t j)
                                LG_LAMBDA_INLINE -> std::uint32_t { return kept[first + length - 1 - j]; };
        for (std::uint32_t chunk = 0; chunk < length; chunk += kUnblendChunk) {
            const std::uint32_t chunk_end = std::min(length, chunk + kUnblendChunk);
            // Entry j's record. (As j % kUnblendChunk, the same place, its address was recomputed in every
            // iteration of every loop; as an offset from the chunk's start it is a pointer stepped along.)
            const auto record = [&](std::uint32_t j)
                                    LG_LAMBDA_INLINE -> Unblended& { return records[j - chunk]; };
            for (std::uint32_t j = chunk; j < chunk_end; ++j) {
                if (j + kPrefetchAhead < length)
                    prefetch_entry(st, begin + walked(j + kPrefetchAhead), channels);
                Unblended& r = record(j);
                r.k = walked(j);
                const std::uint32_t e = begin + r.k;
                P rho;
                const auto reached = raster::splat_hit(st.entry_splat[e], cx, cy, r.smp, rho) &
                                     (I(typename I::I(r.k + 1)) <= s.contributors);
                r.smp.alpha = raster::splat_exponent(rho, reached);  // the exponent waits in the alpha field
            }
            for (std::uint32_t j = chunk; j < chunk_end; ++j) {
                Unblended& r = record(j);
                const auto composited =
                    raster::splat_alpha(st.entry_splat[begin + r.k].opacity, r.smp.alpha, r.smp);
                r.smp.alpha = lane_select(composited, r.smp.alpha, P(0));
                r.smp.screen_branch = r.smp.screen_branch | lane_not(composited);
            }
            for (std::uint32_t j = chunk; j < chunk_end; ++j) {
                Unblended& r = record(j);
                const std::uint32_t e = begin + r.k;
                const P a = r.smp.alpha;
                const raster::SampleValues<P> values =
                    raster::sample_values(s, a > P(0), r.smp.z, &st.entry_color[std::size_t(e) * channels],
                                          channels, st.entry_footprint[e].normal);
                r.grad = raster::unblend_sample(s, a, values, I(typename I::I(e)));
            }
            for (std::uint32_t j = chunk; j < chunk_end; ++j) {
                const Unblended& r = record(j);
                const raster::SplatGradTerms<P> t =
                    raster::splat_grad_terms(st.entry_splat[begin + r.k], cx, cy, r.smp, r.smp.screen_branch,
                                             r.grad.g_alpha, r.grad.g_z);
                P q[kPadded];  // every entry assigned below (a `= {}` here costs a memset per iteration)
                raster::slot_values(t, r.grad, s, q);
                for (int m = SlotLayout::values(C); m < kPadded; ++m) q[m] = P(T(0));
                add_lane_sums<kPadded>(q, &scratch.grads[std::size_t(r.k) * kPadded]);
            }
        }
    }
    // Slots are indexed by emission (contiguous per surfel) so the per-surfel reduction streams. These
    // writes land all over the buffer: through the caches, each first fetched its line from memory (a
    // tenth of the backward's tiles); streamed, whole lines go straight out (the padding as zeros).
    const int line = SlotLayout::line_stride(channels);
    for (std::uint32_t k = 0; k < count; ++k) {
        const T* from = &scratch.grads[std::size_t(k) * kPadded];
        T* to = &slots[std::size_t(st.entry_emission[begin + k]) * line];
        int j = 0;
        for (; j < (C == kMaxChannels ? stride : kPadded); j += kLanes)  // fixed length for 3 and 6
            stream_pack(to + j, load_pack(from + j));
        for (; j < (C == kMaxChannels ? line : SlotLayout::line_stride(C)); j += kLanes)
            stream_pack(to + j, Pack8<T>(T(0)));
    }
    stream_fence();
}

}  // namespace lumigauss::cpu
