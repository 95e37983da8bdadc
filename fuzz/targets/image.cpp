// Images through our reader: PNG (8 and 16 bit), JPEG, Radiance HDR, OpenEXR (io/image.h).
#include <stb/stb_image_write.h>

#include "fuzz_support.h"
#include "lumigauss/io/image.h"

namespace lumigauss::fuzz {
namespace {

Image gradient(int w, int h, int channels, float scale) {
    Image im(w, h, channels);
    for (std::size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = scale * float(i % 17) / 16.0f;
    return im;
}

std::vector<std::string> seeds() {
    std::vector<std::string> out;
    const std::string png8 = scratch_path("seed8.png"), png16 = scratch_path("seed16.png");
    write_png(png8, gradient(9, 7, 3, 1.0f), 8);
    write_png(png16, gradient(5, 4, 1, 1.0f), 16);
    const std::string exr = scratch_path("seed.exr");
    write_exr(exr, gradient(6, 3, 3, 4.0f));
    const Image radiance = gradient(12, 4, 3, 3.0f), tiny = gradient(3, 2, 3, 2.0f);
    const std::string hdr = scratch_path("seed.hdr"), flat = scratch_path("flat.hdr");
    stbi_write_hdr(hdr.c_str(), radiance.width, radiance.height, 3, radiance.pixels.data());
    stbi_write_hdr(flat.c_str(), tiny.width, tiny.height, 3, tiny.pixels.data());
    const std::string jpg = scratch_path("seed.jpg");
    std::vector<unsigned char> bytes(8 * 8 * 3);
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<unsigned char>(i * 7);
    stbi_write_jpg(jpg.c_str(), 8, 8, 3, bytes.data(), 90);
    for (const std::string* p : {&png8, &png16, &exr, &hdr, &flat, &jpg}) out.push_back(read_file(*p));
    return out;
}

void parse(Bytes input) {
    const std::string path = scratch_path("input.img");
    write_file(path, input);
    refuse_cleanly([&] {
        (void)read_image_info(path);
        (void)read_image(path);
    });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(image, seeds, parse)

}  // namespace lumigauss::fuzz
