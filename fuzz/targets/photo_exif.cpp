// EXIF in JPEG and PNG files (io/photo_exif.h): the segment and chunk walks and the TIFF structure.
#include <stb/stb_image_write.h>
#include <zlib.h>

#include <cstdint>
#include <cstdlib>

#include "fuzz_support.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/photo_exif.h"

namespace lumigauss::fuzz {
namespace {

// A camera's EXIF block, little-endian: IFD0 (Orientation 6, the Exif IFD pointer), the Exif IFD
// (ExposureTime 1/250, FNumber 56/10, ISO 200), then the two rationals.
const std::string kCameraBlock = std::string(
    "II\x2a\0\x08\0\0\0"
    "\x02\0"
    "\x12\x01\x03\0\x01\0\0\0\x06\0\0\0"
    "\x69\x87\x04\0\x01\0\0\0\x26\0\0\0"
    "\0\0\0\0"
    "\x03\0"
    "\x9a\x82\x05\0\x01\0\0\0\x50\0\0\0"
    "\x9d\x82\x05\0\x01\0\0\0\x58\0\0\0"
    "\x27\x88\x03\0\x01\0\0\0\xc8\0\0\0"
    "\0\0\0\0"
    "\x01\0\0\0\xfa\0\0\0\x38\0\0\0\x0a\0\0\0",
    96);

std::string big_endian32(std::uint32_t v) {
    return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

std::string jpeg_seed() {
    const std::string path = scratch_path("seed.jpg");
    unsigned char pixels[4 * 4 * 3] = {};
    stbi_write_jpg(path.c_str(), 4, 4, 3, pixels, 90);
    std::string jpeg = read_file(path);
    const std::size_t length = kCameraBlock.size() + 8;
    const std::string app1 = std::string("\xff\xe1") + char(length >> 8) + char(length & 0xff) +
                             std::string("Exif\0\0", 6) + kCameraBlock;
    return jpeg.insert(2, app1);
}

std::string png_seed() {
    const std::string path = scratch_path("seed.png");
    write_png(path, Image(3, 2, 3, 0.5f));
    std::string png = read_file(path);
    const std::string body = "eXIf" + kCameraBlock;
    const auto crc = std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size())));
    return png.insert(33, big_endian32(std::uint32_t(kCameraBlock.size())) + body + big_endian32(crc));
}

std::vector<std::string> seeds() {
    return {jpeg_seed(), png_seed()};
}

void parse(Bytes input) {
    refuse_cleanly([&] { (void)parse_photo_exif(input, "input"); });
    // From a file, damage is a warning (PhotoExif::problem): nothing but a missing file may throw.
    const std::string path = scratch_path("input.jpg");
    write_file(path, input);
    try {
        (void)read_photo_exif(path);
    } catch (const Error&) {
        std::abort();
    }
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(photo_exif, seeds, parse)

}  // namespace lumigauss::fuzz
