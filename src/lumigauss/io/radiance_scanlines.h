#pragma once
// Radiance RGBE (.hdr) files hold their pixels as scanlines, each flat (4 bytes per pixel, with the old
// run-length repeat) or new-style run-length encoded per component. stb_image fills whatever a cut file lacks
// with zeros and reports success, so a truncated panorama would light a scene with a black sky: this walks
// the scanlines without decoding them and says how many are complete.
#include <cstddef>
#include <cstdint>
#include <span>

namespace lumigauss {

struct RadianceLayout {
    int width = 0, height = 0;
    std::size_t data_offset = 0;  // first byte after the resolution line
};

// Parses the header and the resolution line ("-Y H +X W" or another of the eight orientations).
// Returns false when they are malformed or missing.
bool parse_radiance_layout(std::span<const std::uint8_t> file, RadianceLayout& layout);

// How many scanlines of `layout` the bytes after the header hold completely (at most layout.height).
// A scanline whose run lengths overflow its width counts as incomplete, and so do all after it.
int complete_radiance_scanlines(std::span<const std::uint8_t> file, const RadianceLayout& layout);

}  // namespace lumigauss
