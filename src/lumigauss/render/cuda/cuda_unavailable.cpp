// The CUDA backend's entry points in a build without it (cmake/CudaOption.cmake; compiled instead of the
// .cu files): they say why it is missing.
#include "lumigauss/render/cuda/rasterizer_cuda.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

bool cuda_backend_available() {
    return false;
}

std::string cuda_backend_description() {
    return "this build has no CUDA backend (configure with -DLUMIGAUSS_CUDA=ON on a machine with the CUDA "
           "toolkit)";
}

struct CudaRasterizer::Impl {};

CudaRasterizer::CudaRasterizer() {
    throw Error(cuda_backend_description());
}
CudaRasterizer::~CudaRasterizer() = default;
void CudaRasterizer::forward(const Camera&, const SurfelBatch<float>&, const RasterSettings<float>&,
                             RasterImages<float>&) {}
void CudaRasterizer::backward(const RasterImageGrads<float>&, SurfelGrads<float>&) {}
void CudaRasterizer::download_footprints(std::vector<SplatFootprint<float>>&,
                                         std::vector<std::uint8_t>&) const {}
std::size_t CudaRasterizer::intersections() const {
    return 0;
}
const CudaPhaseTimes& CudaRasterizer::phase_ms() const {
    static const CudaPhaseTimes none;
    return none;
}

}  // namespace lumigauss
