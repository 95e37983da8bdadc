// Rasterizer forward and backward on the CUDA backend, on the CPU benchmark's scenes (bench_scene.h). The
// time per iteration is the kernels' device time (CUDA events, no transfers); the transfers to and from
// host memory, which a GPU trainer keeping everything on the device would not make, are counters.
// Run: build/bench/raster_cuda_bench [--benchmark_filter=...]; without a GPU it says why and exits.
#include <benchmark/benchmark.h>

#include <cstdio>

#include "bench_scene.h"
#include "lumigauss/render/cuda/rasterizer_cuda.h"

namespace lumigauss::bench {
namespace {

CudaRasterizer& rasterizer() {
    static CudaRasterizer r;
    return r;
}

struct PhaseSums {
    CudaPhaseTimes sum;
    void add(const CudaPhaseTimes& t) {
        sum.upload += t.upload, sum.project += t.project, sum.bin += t.bin, sum.blend += t.blend;
        sum.download += t.download, sum.grads_upload += t.grads_upload;
        sum.backward_tiles += t.backward_tiles, sum.reduce += t.reduce,
            sum.grads_download += t.grads_download;
    }
    void report(benchmark::State& state) const {
        const auto avg = [](double v) { return benchmark::Counter(v, benchmark::Counter::kAvgIterations); };
        state.counters["project_ms"] = avg(sum.project);
        state.counters["bin_ms"] = avg(sum.bin);
        state.counters["blend_ms"] = avg(sum.blend);
        state.counters["bwd_tiles_ms"] = avg(sum.backward_tiles);
        state.counters["reduce_ms"] = avg(sum.reduce);
        state.counters["transfer_ms"] =
            avg(sum.upload + sum.download + sum.grads_upload + sum.grads_download);
    }
};

// mode 0: forward, 1: backward, 2: both.
void run(benchmark::State& state, int mode) {
    const auto& f = bench_fixture(int(state.range(0)), int(state.range(1)), int(state.range(2)));
    CudaRasterizer& gpu = rasterizer();
    RasterImages<float> img;
    RasterImageGrads<float> g;
    SurfelGrads<float> grads;
    gpu.forward(f.cam, f.surfels, RasterSettings<float>{}, img);  // warm-up: buffers, module load
    g.color.assign(img.color.size(), 0.01f);
    g.alpha.assign(img.alpha.size(), 0.01f);
    g.depth.assign(img.depth.size(), 0.001f);
    g.normal.assign(img.normal.size(), 0.01f);
    gpu.backward(g, grads);
    PhaseSums phases;
    for (auto _ : state) {
        double ms = 0;
        if (mode != 1) {
            gpu.forward(f.cam, f.surfels, RasterSettings<float>{}, img);
            ms += gpu.phase_ms().forward_kernels();
        }
        if (mode != 0) {
            gpu.backward(g, grads);
            ms += gpu.phase_ms().backward_kernels();
        }
        state.SetIterationTime(ms / 1e3);
        phases.add(gpu.phase_ms());
    }
    phases.report(state);
    state.counters["intersections"] = double(gpu.intersections());
}

void BM_CudaForward(benchmark::State& state) {
    run(state, 0);
}
void BM_CudaBackward(benchmark::State& state) {
    run(state, 1);
}
void BM_CudaForwardBackward(benchmark::State& state) {
    run(state, 2);
}

void sizes(benchmark::internal::Benchmark* b) {
    for (int n : {50'000, 200'000, 1'000'000}) {
        b->Args({320, 240, n});
        b->Args({1280, 720, n});
    }
    b->ArgNames({"w", "h", "surfels"})->Unit(benchmark::kMillisecond)->UseManualTime();
}

BENCHMARK(BM_CudaForward)->Apply(sizes);
BENCHMARK(BM_CudaBackward)->Apply(sizes);
BENCHMARK(BM_CudaForwardBackward)->Apply(sizes);

}  // namespace
}  // namespace lumigauss::bench

int main(int argc, char** argv) {
    if (!lumigauss::cuda_backend_available()) {
        std::printf("raster_cuda_bench: skipped: %s\n", lumigauss::cuda_backend_description().c_str());
        return 0;
    }
    std::printf("GPU: %s\n", lumigauss::cuda_backend_description().c_str());
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
