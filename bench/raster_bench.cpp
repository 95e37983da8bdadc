// Rasterizer forward and backward on the CPU: time per call, pixel-surfel pairs per second, and the speed-up
// from 1 to 2 threads. Run: build/bench/raster_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>

#include "bench_scene.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/tile_blocks.h"

namespace lumigauss::bench {
namespace {

// Work counts of one render: (pixel, surfel) pairs inside the surfels' boxes, and vector lanes: 8 per
// (surfel, block of 4 x 2 pixels) pair whose box overlaps the block (tile_blocks.h), all of which a
// forward without early termination would evaluate, and 8 per pair the forward composited into at least
// one pixel of the block, which the backward evaluates.
struct WorkCounts {
    double pairs = 0, lanes = 0, kept_lanes = 0;
};

template <typename T>
WorkCounts work_counts(const RasterState<T>& st) {
    WorkCounts w;
    cpu::BlockLists lists;
    for (int t = 0; t < st.tiles_x * st.tiles_y; ++t) {
        const raster::PixelRect tile = cpu::tile_pixels(t, st.tiles_x, st.view.width, st.view.height);
        for (std::uint32_t e = st.tile_start[t]; e < st.tile_start[t + 1]; ++e) {
            const raster::PixelRect& r = st.entry_footprint[e].rect;
            const int cols = std::min(r.x1, tile.x1) - std::max(r.x0, tile.x0) + 1;
            const int rows = std::min(r.y1, tile.y1) - std::max(r.y0, tile.y0) + 1;
            w.pairs += double(cols) * rows;
        }
        cpu::build_block_lists(st, t, tile, lists);
        w.lanes += 8.0 * double(lists.total());  // eight lanes per block
        if (std::size_t(t) < st.block_entries.size())
            w.kept_lanes += 8.0 * double(st.block_entries[t].size());
    }
    return w;
}

void set_counters(benchmark::State& state, const RasterState<float>& st, const RasterImages<float>& img) {
    const WorkCounts w = work_counts(st);
    const double pairs = w.pairs;
    const double pixels = double(st.view.width) * st.view.height;
    double alpha = 0;
    for (float a : img.alpha) alpha += a;
    state.counters["visible"] = double(std::count(st.visible.begin(), st.visible.end(), 1));
    state.counters["intersections"] = double(st.intersections());
    state.counters["pairs_per_pixel"] = pairs / pixels;
    state.counters["lanes_per_pixel"] = w.lanes / pixels;
    state.counters["kept_lanes_per_pixel"] = w.kept_lanes / pixels;
    state.counters["pairs_per_s"] = benchmark::Counter(pairs, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["mean_alpha"] = alpha / pixels;
}

// Mean milliseconds per call of each phase, as counters. Every benchmark reports all of them (0 for the
// phases it does not run): the CSV output (bench/run_raster_bench.sh) needs the same counters in every row.
struct PhaseSums {
    RasterPhaseTimes sum;
    void add(const RasterPhaseTimes& t) {
        sum.project += t.project, sum.bin += t.bin, sum.gather += t.gather, sum.blend += t.blend;
        sum.backward_tiles += t.backward_tiles, sum.reduce += t.reduce;
    }
    void report(benchmark::State& state) const {
        const auto avg = [](double v) { return benchmark::Counter(v, benchmark::Counter::kAvgIterations); };
        state.counters["project_ms"] = avg(sum.project);
        state.counters["bin_ms"] = avg(sum.bin);
        state.counters["gather_ms"] = avg(sum.gather);
        state.counters["blend_ms"] = avg(sum.blend);
        state.counters["bwd_tiles_ms"] = avg(sum.backward_tiles);
        state.counters["reduce_ms"] = avg(sum.reduce);
    }
};

// Each benchmark calls the rasterizer once before timing it: the state is reused from call to call, as in
// training, and the first call's allocations (hundreds of MiB at 1M surfels, every page faulted in and
// zeroed by the kernel) are not the steady state. At 1M surfels (320x240, 1 thread) that first call took
// 1.5 s against 0.39 s for the next; the mean over the one or two iterations a short run makes included
// it. (At 200k the buffers come back from malloc's heap already mapped, and it did not show.)
void BM_Forward(benchmark::State& state) {
    const auto& f = bench_fixture(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(3)));
    RasterState<float> st;
    RasterImages<float> img;
    rasterize_forward_cpu(f.cam, f.surfels, RasterSettings<float>{}, st, img);  // warm-up (see above)
    PhaseSums phases;
    for (auto _ : state) {
        rasterize_forward_cpu(f.cam, f.surfels, RasterSettings<float>{}, st, img);
        benchmark::DoNotOptimize(img.color.data());
        phases.add(st.phase_ms);
    }
    set_counters(state, st, img);
    phases.report(state);
}

void BM_Backward(benchmark::State& state) {
    const auto& f = bench_fixture(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(3)));
    RasterState<float> st;
    const RasterImages<float> img = rasterize_forward_cpu(f.cam, f.surfels, RasterSettings<float>{}, st);
    RasterImageGrads<float> g;  // a loss on colour, alpha, depth and normals
    g.color.assign(img.color.size(), 0.01f);
    g.alpha.assign(img.alpha.size(), 0.01f);
    g.depth.assign(img.depth.size(), 0.001f);
    g.normal.assign(img.normal.size(), 0.01f);
    PhaseSums phases;
    SurfelGrads<float> grads;
    rasterize_backward_cpu(f.surfels, st, g, grads);  // warm-up (see above BM_Forward)
    for (auto _ : state) {
        rasterize_backward_cpu(f.surfels, st, g, grads);
        benchmark::DoNotOptimize(grads.means.data());
        phases.add(st.phase_ms);
    }
    set_counters(state, st, img);
    phases.report(state);
}

void BM_ForwardBackward(benchmark::State& state) {
    const auto& f = bench_fixture(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(3)));
    RasterState<float> st;
    RasterImages<float> img;
    RasterImageGrads<float> g;
    SurfelGrads<float> grads;
    PhaseSums phases;
    const auto forward_backward = [&] {
        rasterize_forward_cpu(f.cam, f.surfels, RasterSettings<float>{}, st, img);
        g.color.assign(img.color.size(), 0.01f);
        g.alpha.assign(img.alpha.size(), 0.01f);
        rasterize_backward_cpu(f.surfels, st, g, grads);
    };
    forward_backward();  // warm-up (see above BM_Forward)
    for (auto _ : state) {
        forward_backward();
        benchmark::DoNotOptimize(grads.means.data());
        phases.add(st.phase_ms);
    }
    set_counters(state, st, img);
    phases.report(state);
}

void sizes(benchmark::internal::Benchmark* b) {
    for (int threads : {1, 2}) {
        for (int n : {50'000, 200'000, 1'000'000}) {
            b->Args({320, 240, n, threads});
            b->Args({1280, 720, n, threads});
        }
    }
    b->ArgNames({"w", "h", "surfels", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_Forward)->Apply(sizes);
BENCHMARK(BM_Backward)->Apply(sizes);
BENCHMARK(BM_ForwardBackward)->Apply(sizes);

}  // namespace
}  // namespace lumigauss::bench

BENCHMARK_MAIN();
