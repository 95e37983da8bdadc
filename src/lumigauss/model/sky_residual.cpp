#include "lumigauss/model/sky_residual.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

constexpr char kMagic[8] = {'L', 'G', 'S', 'K', 'Y', 'R', '0', '1'};
constexpr std::int32_t kMaxImages = 1 << 24;

void read_exact(std::ifstream& in, const std::string& path, void* data, std::size_t bytes) {
    in.read(static_cast<char*>(data), std::streamsize(bytes));
    if (!in) fail_in_file(path, "truncated sky residual file");
}

}  // namespace

SkyResiduals::SkyResiduals(int num_images)
    : params_(std::size_t(std::max(num_images, 0)) * kRowWidth, 0.0f) {}

Sh4Coeffs<float> SkyResiduals::get(int image) const {
    Sh4Coeffs<float> r;
    const float* row = params_.data() + std::size_t(image) * kRowWidth;
    for (int k = 0; k < kSh4Count; ++k) r.c[k] = {row[3 * k], row[3 * k + 1], row[3 * k + 2]};
    return r;
}

void save_sky_residuals(const std::string& path, const SkyResiduals& residuals) {
    std::string bytes(kMagic, sizeof kMagic);
    const std::int32_t header[2] = {residuals.num_images(), kSh4Count};
    bytes.append(reinterpret_cast<const char*>(header), sizeof header);
    bytes.append(reinterpret_cast<const char*>(residuals.params().data()),
                 residuals.params().size() * sizeof(float));
    write_file_atomically(path, bytes);
}

constexpr std::size_t kRowBytes = SkyResiduals::kRowWidth * sizeof(float);

SkyResiduals load_sky_residuals(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail_in_file(path, "cannot open the sky residual file");
    char magic[sizeof kMagic];
    read_exact(in, path, magic, sizeof magic);
    if (std::memcmp(magic, kMagic, sizeof kMagic) != 0)
        fail_in_file(path, "not a sky residual file (bad magic)");
    std::int32_t header[2];
    read_exact(in, path, header, sizeof header);
    if (header[0] < 0 || header[0] > kMaxImages || header[1] != kSh4Count)
        fail_in_file(path, "sky residual dimensions are not N photos x 25 coefficients");
    const std::size_t expected = sizeof magic + sizeof header + std::size_t(header[0]) * kRowBytes;
    if (std::filesystem::file_size(path) != expected)
        fail_in_file(path, "holds " + std::to_string(std::filesystem::file_size(path)) + " bytes, but " +
                               std::to_string(header[0]) + " photos' residuals take " +
                               std::to_string(expected) + " (truncated, or a wrong photo count)");
    SkyResiduals r(header[0]);
    read_exact(in, path, r.params().data(), r.params().size() * sizeof(float));
    if (in.peek() != std::ifstream::traits_type::eof())
        fail_in_file(path, "trailing bytes after the sky residuals");
    return r;
}

}  // namespace lumigauss
