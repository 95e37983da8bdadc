#include "lumigauss/viewer/url_path.h"

#include <algorithm>
#include <string>

namespace lumigauss::view {
namespace {

int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// The raw characters a path may hold (RFC 3986 pchar plus '/'), '%' starting an escape.
bool allowed_raw_path_char(char c) {
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) return true;
    const std::string_view extra = "-._~!$&'()*+,;=:@/%";
    return extra.find(c) != std::string_view::npos;
}

// Bytes an escape may not produce in a path: they would smuggle a separator, a second decoding round or a
// byte that file systems and logs treat specially.
bool forbidden_decoded_path_byte(unsigned char c) {
    return c < 0x20 || c == 0x7f || c >= 0x80 || c == '/' || c == '\\' || c == '%';
}

std::optional<std::string> decode_path(std::string_view raw) {
    std::string out;
    for (std::size_t i = 0; i < raw.size(); ++i) {
        const char c = raw[i];
        if (!allowed_raw_path_char(c)) return std::nullopt;
        if (c != '%') {
            out += c;
            continue;
        }
        const int hi = i + 1 < raw.size() ? hex_value(raw[i + 1]) : -1;
        const int lo = i + 2 < raw.size() ? hex_value(raw[i + 2]) : -1;
        if (hi < 0 || lo < 0) return std::nullopt;
        const auto byte = static_cast<unsigned char>(hi * 16 + lo);
        if (forbidden_decoded_path_byte(byte)) return std::nullopt;
        out += static_cast<char>(byte);
        i += 2;
    }
    return out;
}

// Every segment of a decoded path (leading '/' removed) must be a plain name.
bool plain_segments(std::string_view path) {
    if (path.empty()) return true;  // the root
    std::size_t start = 0;
    while (start <= path.size()) {
        const std::size_t end = std::min(path.find('/', start), path.size());
        const std::string_view seg = path.substr(start, end - start);
        if (seg.empty() || seg.front() == '.') return false;  // "//", ".", "..", hidden names
        start = end + 1;
    }
    return true;
}

}  // namespace

std::optional<std::string> percent_decode(std::string_view text, bool plus_is_space) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '+' && plus_is_space) {
            out += ' ';
        } else if (c != '%') {
            if (c == '\0') return std::nullopt;
            out += c;
        } else {
            const int hi = i + 1 < text.size() ? hex_value(text[i + 1]) : -1;
            const int lo = i + 2 < text.size() ? hex_value(text[i + 2]) : -1;
            if (hi < 0 || lo < 0 || (hi == 0 && lo == 0)) return std::nullopt;
            out += static_cast<char>(hi * 16 + lo);
            i += 2;
        }
    }
    return out;
}

std::optional<RequestTarget> parse_request_target(std::string_view target) {
    if (target.empty() || target.front() != '/') return std::nullopt;
    if (target.find('#') != std::string_view::npos) return std::nullopt;
    const std::size_t q = target.find('?');
    const std::string_view raw_path = target.substr(0, q);
    if (raw_path.size() > kMaxPathBytes) return std::nullopt;
    auto decoded = decode_path(raw_path.substr(1));
    if (!decoded || !plain_segments(*decoded)) return std::nullopt;
    RequestTarget out;
    out.path = std::move(*decoded);
    if (q != std::string_view::npos) out.query = std::string(target.substr(q + 1));
    return out;
}

std::optional<std::map<std::string, std::string>> parse_query(std::string_view query) {
    std::map<std::string, std::string> out;
    std::size_t start = 0;
    while (start < query.size()) {
        const std::size_t end = std::min(query.find('&', start), query.size());
        const std::string_view part = query.substr(start, end - start);
        start = end + 1;
        if (part.empty()) continue;
        const std::size_t eq = part.find('=');
        auto key = percent_decode(part.substr(0, eq), true);
        auto value = eq == std::string_view::npos ? std::optional<std::string>("")
                                                  : percent_decode(part.substr(eq + 1), true);
        if (!key || !value) return std::nullopt;
        out[*key] = std::move(*value);
    }
    return out;
}

}  // namespace lumigauss::view
