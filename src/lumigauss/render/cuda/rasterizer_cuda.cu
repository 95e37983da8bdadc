// The CUDA backend's entry points: uploads, the passes in order, downloads, and their timing.
#include "lumigauss/render/cuda/rasterizer_cuda.h"

#include <string>

#include "lumigauss/render/cuda/raster_state_cuda.cuh"

namespace lumigauss {
namespace {

// The phases' boundaries, as events on the rasterizer's stream.
class PhaseEvents {
  public:
    static constexpr int kCount = 6;
    PhaseEvents() {
        for (cudaEvent_t& e : events_) cuda::check(cudaEventCreate(&e), "cudaEventCreate");
    }
    ~PhaseEvents() {
        for (cudaEvent_t e : events_) cudaEventDestroy(e);
    }
    PhaseEvents(const PhaseEvents&) = delete;
    PhaseEvents& operator=(const PhaseEvents&) = delete;
    void mark(int i, cudaStream_t stream) {
        cuda::check(cudaEventRecord(events_[i], stream), "cudaEventRecord");
    }
    double ms(int from, int to) const {
        float ms = 0;
        cuda::check(cudaEventElapsedTime(&ms, events_[from], events_[to]), "cudaEventElapsedTime");
        return double(ms);
    }

  private:
    cudaEvent_t events_[kCount];
};

void upload_or_clear(cuda::DeviceBuffer<float>& to, const std::vector<float>& from, std::size_t expected,
                     const char* map, cudaStream_t stream) {
    if (!from.empty() && from.size() != expected)
        throw Error(std::string("CUDA rasterizer backward: the gradient of the ") + map + " map has " +
                    std::to_string(from.size()) + " values, the forward rendered " +
                    std::to_string(expected));
    to.upload(from, stream);  // empty: size 0, read as zero
}

}  // namespace

bool cuda_backend_available() {
    int count = 0;
    return cudaGetDeviceCount(&count) == cudaSuccess && count > 0;
}

std::string cuda_backend_description() {
    int count = 0;
    const cudaError_t status = cudaGetDeviceCount(&count);
    if (status != cudaSuccess) return std::string("no usable GPU: ") + cudaGetErrorString(status);
    if (count == 0) return "no GPU found";
    int device = 0;
    cudaGetDevice(&device);
    cudaDeviceProp prop{};
    cuda::check(cudaGetDeviceProperties(&prop, device), "cudaGetDeviceProperties");
    return std::string(prop.name) + ", compute capability " + std::to_string(prop.major) + "." +
           std::to_string(prop.minor) + ", " + std::to_string(prop.multiProcessorCount) +
           " multiprocessors, " + std::to_string(prop.totalGlobalMem >> 20) + " MiB";
}

struct CudaRasterizer::Impl {
    cuda::RasterStateCuda st;
    cudaStream_t stream = nullptr;
    PhaseEvents events;
    CudaPhaseTimes times;
    bool has_forward = false;

    Impl() { cuda::check(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking), "cudaStreamCreate"); }
    ~Impl() { cudaStreamDestroy(stream); }
};

CudaRasterizer::CudaRasterizer() {
    if (!cuda_backend_available()) throw Error("CUDA rasterizer: " + cuda_backend_description());
    impl_ = std::make_unique<Impl>();
}
CudaRasterizer::~CudaRasterizer() = default;

void CudaRasterizer::forward(const Camera& camera, const SurfelBatch<float>& surfels,
                             const RasterSettings<float>& settings, RasterImages<float>& images) {
    check_surfel_batch(surfels);
    const int channels = surfels.channels;
    if (!settings.background.empty() && int(settings.background.size()) != channels)
        throw Error("CUDA rasterizer: the background has " + std::to_string(settings.background.size()) +
                    " values for " + std::to_string(channels) + " channels");
    Impl& m = *impl_;
    cuda::RasterStateCuda& st = m.st;
    const cudaStream_t stream = m.stream;
    // As the CPU backend: the view rounded to float, and the projection in double from that.
    st.view_f = pinhole_view<float>(camera);
    st.view = raster::cast_view<double>(st.view_f);
    st.width = camera.width, st.height = camera.height, st.channels = channels;
    st.tiles_x = (camera.width + raster::kTileSize - 1) / raster::kTileSize;
    st.tiles_y = (camera.height + raster::kTileSize - 1) / raster::kTileSize;
    st.surfels = surfels.size();
    for (int c = 0; c < kMaxChannels; ++c)
        st.background[c] = c < channels && !settings.background.empty() ? settings.background[c] : 0.0f;

    m.events.mark(0, stream);
    st.means.upload(surfels.means, stream);
    st.quats.upload(surfels.quats, stream);
    st.scales.upload(surfels.scales, stream);
    st.opacities.upload(surfels.opacities, stream);
    st.colors.upload(surfels.colors, stream);
    m.events.mark(1, stream);
    cuda::project_surfels(st, stream);
    m.events.mark(2, stream);
    cuda::bin_surfels(st, stream);
    m.events.mark(3, stream);
    cuda::blend_tiles(st, stream);
    m.events.mark(4, stream);
    images.width = camera.width, images.height = camera.height, images.channels = channels;
    st.color.download(images.color, stream);
    st.alpha.download(images.alpha, stream);
    st.depth.download(images.depth, stream);
    st.median_depth.download(images.median_depth, stream);
    st.normal.download(images.normal, stream);
    st.distortion.download(images.distortion, stream);
    m.events.mark(5, stream);
    cuda::check(cudaStreamSynchronize(stream), "forward");
    m.times.upload = m.events.ms(0, 1);
    m.times.project = m.events.ms(1, 2);
    m.times.bin = m.events.ms(2, 3);
    m.times.blend = m.events.ms(3, 4);
    m.times.download = m.events.ms(4, 5);
    m.has_forward = true;
}

void CudaRasterizer::backward(const RasterImageGrads<float>& grads, SurfelGrads<float>& out) {
    Impl& m = *impl_;
    if (!m.has_forward) throw Error("CUDA rasterizer: backward called before any forward");
    cuda::RasterStateCuda& st = m.st;
    const cudaStream_t stream = m.stream;
    const std::size_t np = std::size_t(st.width) * st.height;
    m.events.mark(0, stream);
    upload_or_clear(st.g_color, grads.color, np * st.channels, "colour", stream);
    upload_or_clear(st.g_alpha, grads.alpha, np, "alpha", stream);
    upload_or_clear(st.g_depth, grads.depth, np, "depth", stream);
    upload_or_clear(st.g_median_depth, grads.median_depth, np, "median depth", stream);
    upload_or_clear(st.g_normal, grads.normal, 3 * np, "normal", stream);
    upload_or_clear(st.g_distortion, grads.distortion, np, "distortion", stream);
    m.events.mark(1, stream);
    cuda::backward_tiles(st, stream);
    m.events.mark(2, stream);
    cuda::reduce_surfel_gradients(st, stream);
    m.events.mark(3, stream);
    st.d_means.download(out.means, stream);
    st.d_quats.download(out.quats, stream);
    st.d_scales.download(out.scales, stream);
    st.d_opacities.download(out.opacities, stream);
    st.d_colors.download(out.colors, stream);
    st.d_mean2d.download(out.mean2d, stream);
    m.events.mark(4, stream);
    cuda::check(cudaStreamSynchronize(stream), "backward");
    m.times.grads_upload = m.events.ms(0, 1);
    m.times.backward_tiles = m.events.ms(1, 2);
    m.times.reduce = m.events.ms(2, 3);
    m.times.grads_download = m.events.ms(3, 4);
}

void CudaRasterizer::download_footprints(std::vector<SplatFootprint<float>>& footprints,
                                         std::vector<std::uint8_t>& visible) const {
    const Impl& m = *impl_;
    if (!m.has_forward) throw Error("CUDA rasterizer: footprints asked for before any forward");
    std::vector<std::uint32_t> tiles;
    m.st.footprints.download(footprints, m.stream);
    m.st.tiles_touched.download(tiles, m.stream);
    cuda::check(cudaStreamSynchronize(m.stream), "footprints");
    visible.resize(tiles.size());
    for (std::size_t i = 0; i < tiles.size(); ++i) visible[i] = tiles[i] != 0 ? 1 : 0;
}

std::size_t CudaRasterizer::intersections() const {
    return impl_->st.entries;
}

const CudaPhaseTimes& CudaRasterizer::phase_ms() const {
    return impl_->times;
}

}  // namespace lumigauss
