#pragma once
// What a photo's EXIF says that reconstruction can use: how the camera was held when the pixels were stored
// (the Orientation tag) and how the photo was exposed (exposure time, aperture, ISO).
//
// Read from a JPEG's APP1 "Exif" segment or a PNG's eXIf chunk, walking only the file's head (segment and
// chunk headers up to the image data), so the cost is a few small reads per photo and the memory is bounded
// by the block's size (at most 64 KiB in a JPEG, kMaxExifBytes in a PNG). Other formats have no EXIF here.
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace lumigauss {

// A PNG eXIf chunk larger than this is not EXIF a camera wrote; it is skipped as damaged.
inline constexpr std::uint32_t kMaxExifBytes = 1u << 20;

struct PhotoExif {
    // EXIF Orientation, 1 to 8 (1: the stored pixels are upright); 1 when absent or out of range.
    int orientation = 1;
    std::optional<double> exposure_time_s;  // ExposureTime, seconds (> 0)
    std::optional<double> f_number;         // FNumber (> 0)
    std::optional<double> iso;              // PhotographicSensitivity (ISOSpeedRatings), or ISOSpeed
    // Set when the file has an EXIF block that could not be read (what is wrong with it); the fields above
    // are then the defaults. Photos with damaged EXIF are common and otherwise fine, so this is a warning.
    std::string problem;

    bool has_exposure() const { return exposure_time_s && f_number; }
    // The exposure value at ISO 100, EV100 = log2(N^2 / t) - log2(ISO / 100) (ISO 100 when unknown): one more
    // EV is half the light per pixel for the same scene. Empty without exposure time and aperture.
    std::optional<double> ev100() const;
};

// The EXIF of the photo at `path` (JPEG or PNG; any other file gives the defaults). Throws Error naming the
// file only when it cannot be opened; a damaged EXIF block sets `problem` instead.
PhotoExif read_photo_exif(const std::string& path);

// Parses an EXIF block from its TIFF header ("II*\0" or "MM\0*") on: IFD0's Orientation and the Exif IFD's
// exposure tags. Throws Error (naming `source`) for a block whose structure is damaged: bad byte order mark,
// offsets or counts outside the block. Unknown tags and tags of unexpected types are ignored.
PhotoExif parse_exif_tiff(std::span<const std::uint8_t> tiff, const std::string& source);

// The EXIF of a whole JPEG or PNG file held in memory (what read_photo_exif does with a file's bytes). Throws
// Error naming `source` for a damaged EXIF block or a cut file; `problem` stays empty.
PhotoExif parse_photo_exif(std::span<const std::uint8_t> file, const std::string& source);

}  // namespace lumigauss
