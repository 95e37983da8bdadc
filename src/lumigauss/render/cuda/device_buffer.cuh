#pragma once
// Device memory for the CUDA backend: CUDA errors as lumigauss::Error, and a growable buffer.
#include <cuda_runtime.h>

#include <cstddef>
#include <string>
#include <vector>

#include "lumigauss/util/error.h"

namespace lumigauss::cuda {

inline void check(cudaError_t status, const char* what) {
    if (status != cudaSuccess)
        throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorName(status) + " (" +
                    cudaGetErrorString(status) + ")");
}
// After a kernel launch: a bad launch configuration shows here, a fault in the kernel at the next sync.
inline void check_launch(const char* kernel) {
    check(cudaGetLastError(), kernel);
}

// A device array that keeps its memory when resized smaller, and grows by half again beyond what is asked
// when it must grow (sizes vary from view to view in a training loop).
template <typename T>
class DeviceBuffer {
  public:
    DeviceBuffer() = default;
    ~DeviceBuffer() {
        if (data_) cudaFree(data_);
    }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;

    void resize(std::size_t n) {
        if (n > capacity_) {
            if (data_) cudaFree(data_);
            data_ = nullptr;
            const std::size_t grown = n + n / 2;
            check(cudaMalloc(reinterpret_cast<void**>(&data_), grown * sizeof(T)), "cudaMalloc");
            capacity_ = grown;
        }
        size_ = n;
    }
    void upload(const T* host, std::size_t n, cudaStream_t stream) {
        resize(n);
        if (n) check(cudaMemcpyAsync(data_, host, n * sizeof(T), cudaMemcpyHostToDevice, stream), "upload");
    }
    void upload(const std::vector<T>& host, cudaStream_t stream) { upload(host.data(), host.size(), stream); }
    void download(std::vector<T>& host, cudaStream_t stream) const {
        host.resize(size_);
        if (size_)
            check(cudaMemcpyAsync(host.data(), data_, size_ * sizeof(T), cudaMemcpyDeviceToHost, stream),
                  "download");
    }
    void clear(cudaStream_t stream) {
        if (size_) check(cudaMemsetAsync(data_, 0, size_ * sizeof(T), stream), "clear");
    }

    T* data() { return data_; }
    const T* data() const { return data_; }
    std::size_t size() const { return size_; }

  private:
    T* data_ = nullptr;
    std::size_t size_ = 0, capacity_ = 0;
};

}  // namespace lumigauss::cuda
