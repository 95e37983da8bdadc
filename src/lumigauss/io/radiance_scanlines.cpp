#include "lumigauss/io/radiance_scanlines.h"

#include <charconv>
#include <string_view>

namespace lumigauss {

namespace {

// One header line (without its newline) starting at `pos`; advances `pos` past the newline. Returns false at
// the end of the data without a newline.
bool next_line(std::span<const std::uint8_t> file, std::size_t& pos, std::string_view& line) {
    const std::size_t start = pos;
    while (pos < file.size() && file[pos] != '\n') ++pos;
    if (pos >= file.size()) return false;
    line = std::string_view(reinterpret_cast<const char*>(file.data()) + start, pos - start);
    ++pos;
    return true;
}

// "-Y 480 +X 640": two signed axis letters, each followed by a positive count.
bool parse_resolution(std::string_view line, RadianceLayout& layout) {
    int counts[2] = {};
    char axes[2] = {};
    std::size_t p = 0;
    for (int k = 0; k < 2; ++k) {
        while (p < line.size() && line[p] == ' ') ++p;
        if (p + 2 > line.size() || (line[p] != '-' && line[p] != '+') ||
            (line[p + 1] != 'X' && line[p + 1] != 'Y'))
            return false;
        axes[k] = line[p + 1];
        p += 2;
        while (p < line.size() && line[p] == ' ') ++p;
        const auto [end, ec] = std::from_chars(line.data() + p, line.data() + line.size(), counts[k]);
        if (ec != std::errc() || counts[k] <= 0) return false;
        p = std::size_t(end - line.data());
    }
    if (axes[0] == axes[1]) return false;
    // The first axis counts the scanlines, the second the pixels in each.
    layout.height = counts[0];
    layout.width = counts[1];
    return true;
}

// Skips one new-style RLE scanline (four components, each runs and literals adding up to `width`).
bool skip_rle_scanline(std::span<const std::uint8_t> file, std::size_t& pos, int width) {
    pos += 4;  // 2 2 hi lo
    for (int component = 0; component < 4; ++component) {
        int filled = 0;
        while (filled < width) {
            if (pos >= file.size()) return false;
            const int code = file[pos++];
            const bool run = code > 128;
            const int count = run ? code - 128 : code;
            if (count == 0 || filled + count > width) return false;
            const std::size_t bytes = run ? 1 : std::size_t(count);
            if (file.size() - pos < bytes) return false;
            pos += bytes;
            filled += count;
        }
    }
    return true;
}

// Skips one flat scanline: RGBE pixels, where (1, 1, 1, n) repeats the previous pixel n << shift times.
bool skip_flat_scanline(std::span<const std::uint8_t> file, std::size_t& pos, int width) {
    int filled = 0, shift = 0;
    while (filled < width) {
        if (file.size() - pos < 4) return false;
        const std::uint8_t* p = file.data() + pos;
        pos += 4;
        if (p[0] == 1 && p[1] == 1 && p[2] == 1) {
            if (filled == 0 || shift > 24) return false;
            const long long repeat = static_cast<long long>(p[3]) << shift;
            if (filled + repeat > width) return false;
            filled += int(repeat);
            shift += 8;
        } else {
            ++filled;
            shift = 0;
        }
    }
    return true;
}

}  // namespace

bool parse_radiance_layout(std::span<const std::uint8_t> file, RadianceLayout& layout) {
    std::size_t pos = 0;
    std::string_view line;
    if (!next_line(file, pos, line) || !line.starts_with("#?")) return false;
    while (true) {  // header lines end with an empty one
        if (!next_line(file, pos, line)) return false;
        if (line.empty()) break;
    }
    if (!next_line(file, pos, line) || !parse_resolution(line, layout)) return false;
    layout.data_offset = pos;
    return true;
}

int complete_radiance_scanlines(std::span<const std::uint8_t> file, const RadianceLayout& layout) {
    std::size_t pos = layout.data_offset;
    const int width = layout.width;
    for (int row = 0; row < layout.height; ++row) {
        const bool rle = width >= 8 && width < 32768 && file.size() - pos >= 4 && file[pos] == 2 &&
                         file[pos + 1] == 2 && ((file[pos + 2] << 8) | file[pos + 3]) == width;
        const bool complete =
            rle ? skip_rle_scanline(file, pos, width) : skip_flat_scanline(file, pos, width);
        if (!complete) return row;
    }
    return layout.height;
}

}  // namespace lumigauss
