#include "lumigauss/io/photo_exif.h"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <vector>

#include "lumigauss/util/error.h"

namespace lumigauss {

std::optional<double> PhotoExif::ev100() const {
    if (!has_exposure()) return std::nullopt;
    const double n = *f_number, t = *exposure_time_s;
    return std::log2(n * n / t) - std::log2(iso.value_or(100.0) / 100.0);
}

namespace {

// ---- The TIFF structure inside an EXIF block --------------------------------------------------------------

constexpr std::uint16_t kTagOrientation = 0x0112;
constexpr std::uint16_t kTagExifIfd = 0x8769;
constexpr std::uint16_t kTagExposureTime = 0x829A;
constexpr std::uint16_t kTagFNumber = 0x829D;
constexpr std::uint16_t kTagIsoSpeedRatings = 0x8827;
constexpr std::uint16_t kTagIsoSpeed = 0x8833;

enum TiffType : std::uint16_t { kShort = 3, kLong = 4, kRational = 5, kIfd = 13 };

// Bytes per value of each TIFF field type (0: unknown type, whose entries are skipped).
std::uint64_t type_size(std::uint16_t type) {
    switch (type) {
        case 1:
        case 2:
        case 6:
        case 7:
            return 1;  // BYTE, ASCII, SBYTE, UNDEFINED
        case 3:
        case 8:
            return 2;  // SHORT, SSHORT
        case 4:
        case 9:
        case 11:
        case 13:
            return 4;  // LONG, SLONG, FLOAT, IFD
        case 5:
        case 10:
        case 12:
            return 8;  // RATIONAL, SRATIONAL, DOUBLE
        default:
            return 0;
    }
}

class TiffBlock {
  public:
    TiffBlock(std::span<const std::uint8_t> bytes, const std::string& source)
        : bytes_(bytes), source_(source) {
        if (bytes.size() < 8) fail("EXIF block shorter than its 8-byte TIFF header");
        if (bytes[0] == 'I' && bytes[1] == 'I')
            little_ = true;
        else if (bytes[0] == 'M' && bytes[1] == 'M')
            little_ = false;
        else
            fail("EXIF block without a TIFF byte-order mark (II or MM)");
        if (u16(2) != 42) fail("EXIF block: TIFF magic number is not 42");
    }

    std::uint32_t first_ifd() const { return u32(4); }

    struct Entry {
        std::uint16_t tag, type;
        std::uint32_t count;
        std::uint64_t value_offset;  // where the values are: inside the entry when they fit in 4 bytes
    };

    // The entries of the IFD at `offset` whose type is known. An entry or value past the block is damage: the
    // whole block is refused, as a reader cannot tell what else is wrong.
    std::vector<Entry> ifd(std::uint64_t offset) const {
        need(offset, 2, "an IFD");
        const std::uint16_t n = u16(offset);
        need(offset + 2, std::uint64_t(n) * 12, "an IFD's entries");
        std::vector<Entry> entries;
        entries.reserve(n);
        for (std::uint16_t i = 0; i < n; ++i) {
            const std::uint64_t at = offset + 2 + std::uint64_t(i) * 12;
            Entry e{u16(at), u16(at + 2), u32(at + 4), at + 8};
            const std::uint64_t size = type_size(e.type) * e.count;
            if (type_size(e.type) == 0) continue;
            if (size > 4) e.value_offset = u32(at + 8);
            need(e.value_offset, size, "a tag's values");
            entries.push_back(e);
        }
        return entries;
    }

    std::uint16_t u16(std::uint64_t at) const {
        need(at, 2, "a 16-bit value");
        const std::uint8_t a = bytes_[at], b = bytes_[at + 1];
        return little_ ? std::uint16_t(a | b << 8) : std::uint16_t(b | a << 8);
    }
    std::uint32_t u32(std::uint64_t at) const {
        const std::uint32_t lo = u16(little_ ? at : at + 2), hi = u16(little_ ? at + 2 : at);
        return lo | hi << 16;
    }
    // An unsigned rational; empty when its denominator is 0.
    std::optional<double> rational(std::uint64_t at) const {
        const std::uint32_t num = u32(at), den = u32(at + 4);
        if (den == 0) return std::nullopt;
        return double(num) / double(den);
    }

  private:
    void need(std::uint64_t at, std::uint64_t length, const char* what) const {
        if (at > bytes_.size() || length > bytes_.size() - at)
            fail(std::string("EXIF block: ") + what + " lies outside the block");
    }
    [[noreturn]] void fail(const std::string& what) const { fail_in_file(source_, what); }

    std::span<const std::uint8_t> bytes_;
    const std::string& source_;
    bool little_ = true;
};

std::optional<double> positive(std::optional<double> v) {
    if (v && std::isfinite(*v) && *v > 0) return v;
    return std::nullopt;
}

void read_exposure_tags(const TiffBlock& tiff, std::uint64_t offset, PhotoExif& exif) {
    std::optional<double> iso_speed;
    for (const TiffBlock::Entry& e : tiff.ifd(offset)) {
        if (e.count == 0) continue;
        if (e.tag == kTagExposureTime && e.type == kRational)
            exif.exposure_time_s = positive(tiff.rational(e.value_offset));
        else if (e.tag == kTagFNumber && e.type == kRational)
            exif.f_number = positive(tiff.rational(e.value_offset));
        else if (e.tag == kTagIsoSpeedRatings && e.type == kShort) {
            const std::uint16_t v = tiff.u16(e.value_offset);
            // 65535: "too large for this tag", the value is in ISOSpeed.
            if (v != 0 && v != 65535) exif.iso = double(v);
        } else if (e.tag == kTagIsoSpeed && e.type == kLong)
            iso_speed = positive(double(tiff.u32(e.value_offset)));
    }
    if (!exif.iso) exif.iso = iso_speed;
}

// ---- Finding the block in a JPEG or PNG -------------------------------------------------------------------

// Bytes read in order from a file or from memory; read() and skip() return false at the end.
class ByteStream {
  public:
    virtual ~ByteStream() = default;
    virtual bool read(std::uint8_t* out, std::size_t n) = 0;
    virtual bool skip(std::uint64_t n) = 0;
};

class MemoryStream final : public ByteStream {
  public:
    explicit MemoryStream(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
    bool read(std::uint8_t* out, std::size_t n) override {
        if (n == 0)
            return true;  // `out` may be the null data() of an empty vector (found by fuzz.photo_exif)
        if (n > bytes_.size() - at_) return false;
        std::memcpy(out, bytes_.data() + at_, n);
        at_ += n;
        return true;
    }
    bool skip(std::uint64_t n) override {
        if (n > bytes_.size() - at_) return false;
        at_ += std::size_t(n);
        return true;
    }

  private:
    std::span<const std::uint8_t> bytes_;
    std::size_t at_ = 0;
};

class FileStream final : public ByteStream {
  public:
    explicit FileStream(std::ifstream& in) : in_(in) {}
    bool read(std::uint8_t* out, std::size_t n) override {
        if (n == 0) return true;
        in_.read(reinterpret_cast<char*>(out), std::streamsize(n));
        return std::size_t(in_.gcount()) == n;
    }
    bool skip(std::uint64_t n) override {
        in_.seekg(std::streamoff(n), std::ios::cur);
        return bool(in_);
    }

  private:
    std::ifstream& in_;
};

std::uint32_t big_endian(const std::uint8_t* p, int bytes) {
    std::uint32_t v = 0;
    for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
    return v;
}

// The TIFF bytes of a JPEG's first APP1 "Exif" segment, walking the segments before the scan data; empty
// when there is none.
std::vector<std::uint8_t> jpeg_exif(ByteStream& in, const std::string& source) {
    static constexpr std::uint8_t kSos = 0xDA, kEoi = 0xD9, kApp1 = 0xE1;
    for (;;) {
        std::uint8_t marker[2];
        if (!in.read(marker, 2)) fail_in_file(source, "JPEG ends before its image data");
        if (marker[0] != 0xFF) fail_in_file(source, "JPEG: a segment does not start with a marker");
        while (marker[1] == 0xFF)  // fill bytes before the marker code
            if (!in.read(&marker[1], 1)) fail_in_file(source, "JPEG ends before its image data");
        const std::uint8_t code = marker[1];
        if (code == kSos || code == kEoi) return {};
        if ((code >= 0xD0 && code <= 0xD7) || code == 0x01 || code == 0x00) continue;  // no length field
        std::uint8_t length_bytes[2];
        if (!in.read(length_bytes, 2)) fail_in_file(source, "JPEG ends inside a segment header");
        const std::uint32_t length = big_endian(length_bytes, 2);
        if (length < 2) fail_in_file(source, "JPEG: a segment's length is less than 2");
        if (code == kApp1) {
            std::vector<std::uint8_t> payload(length - 2);  // at most 64 KiB
            if (!in.read(payload.data(), payload.size()))
                fail_in_file(source, "JPEG ends inside its APP1 segment");
            static constexpr std::array<std::uint8_t, 6> kExifId{'E', 'x', 'i', 'f', 0, 0};
            if (payload.size() >= 6 && std::equal(kExifId.begin(), kExifId.end(), payload.begin()))
                return std::vector<std::uint8_t>(payload.begin() + 6, payload.end());
        } else if (!in.skip(length - 2)) {
            fail_in_file(source, "JPEG ends inside a segment");
        }
    }
}

// The bytes of a PNG's eXIf chunk, walking the chunks before the image data; empty when there is none.
std::vector<std::uint8_t> png_exif(ByteStream& in, const std::string& source) {
    for (;;) {
        std::uint8_t header[8];
        if (!in.read(header, 8)) fail_in_file(source, "PNG ends before its image data");
        const std::uint32_t length = big_endian(header, 4);
        const std::string type(reinterpret_cast<const char*>(header + 4), 4);
        if (type == "IDAT" || type == "IEND") return {};
        if (length > 0x7FFFFFFFu) fail_in_file(source, "PNG: a chunk declares more than 2^31 bytes");
        if (type == "eXIf") {
            if (length > kMaxExifBytes)
                fail_in_file(source, "PNG: eXIf chunk of " + std::to_string(length) + " bytes (at most " +
                                         std::to_string(kMaxExifBytes) + " are read)");
            std::vector<std::uint8_t> block(length);
            if (!in.read(block.data(), block.size())) fail_in_file(source, "PNG ends inside its eXIf chunk");
            return block;
        }
        if (!in.skip(std::uint64_t(length) + 4)) fail_in_file(source, "PNG ends inside a chunk");
    }
}

enum class Container { Jpeg, Png, Other };

Container sniff(const std::uint8_t* head, std::size_t n) {
    static constexpr std::uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (n >= 2 && head[0] == 0xFF && head[1] == 0xD8) return Container::Jpeg;
    if (n >= 8 && std::memcmp(head, kPng, 8) == 0) return Container::Png;
    return Container::Other;
}

PhotoExif exif_of_stream(ByteStream& in, const std::string& source) {
    std::uint8_t head[8] = {};
    std::size_t n = 0;
    if (!in.read(head, 2)) return {};
    n = 2;
    if (head[0] != 0xFF) {
        if (!in.read(head + 2, 6)) return {};
        n = 8;
    }
    std::vector<std::uint8_t> block;
    switch (sniff(head, n)) {
        case Container::Jpeg:
            block = jpeg_exif(in, source);
            break;
        case Container::Png:
            block = png_exif(in, source);
            break;
        case Container::Other:
            return {};
    }
    if (block.empty()) return {};
    return parse_exif_tiff(block, source);
}

}  // namespace

PhotoExif parse_exif_tiff(std::span<const std::uint8_t> bytes, const std::string& source) {
    const TiffBlock tiff(bytes, source);
    PhotoExif exif;
    std::optional<std::uint32_t> exif_ifd;
    for (const TiffBlock::Entry& e : tiff.ifd(tiff.first_ifd())) {
        if (e.count == 0) continue;
        if (e.tag == kTagOrientation && e.type == kShort) {
            const std::uint16_t v = tiff.u16(e.value_offset);
            if (v >= 1 && v <= 8) exif.orientation = v;
        } else if (e.tag == kTagExifIfd && (e.type == kLong || e.type == kIfd)) {
            exif_ifd = tiff.u32(e.value_offset);
        }
    }
    if (exif_ifd) read_exposure_tags(tiff, *exif_ifd, exif);
    return exif;
}

PhotoExif parse_photo_exif(std::span<const std::uint8_t> file, const std::string& source) {
    MemoryStream in(file);
    return exif_of_stream(in, source);
}

PhotoExif read_photo_exif(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail_in_file(path, "cannot open the image file");
    FileStream stream(in);
    try {
        return exif_of_stream(stream, path);
    } catch (const Error& e) {
        PhotoExif damaged;
        damaged.problem = e.what();
        return damaged;
    }
}

}  // namespace lumigauss
