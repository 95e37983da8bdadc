#pragma once
// Request targets of the viewer's HTTP server, decoded so that nothing outside the served content can be
// named. The server serves only in-memory content (embedded web assets and generated payloads) looked up by
// exact name, so even a path that got through here could not reach the file system; these rules refuse
// every traversal-looking target anyway, so that a refusal is visible (400) instead of a silent 404:
//   * origin-form only: the target starts with '/'; absolute-form ("http://...") and '*' are refused;
//   * raw characters: RFC 3986 unreserved, sub-delims, ':', '@', '/' and '%'; no control byte, space,
//     backslash or non-ASCII byte;
//   * percent-escapes must be two hex digits; an escape that decodes to NUL, '/', '\', '%', a control
//     byte or a non-ASCII byte is refused (no encoded slashes, no double decoding);
//   * after decoding, no segment is empty (no "//"), "." or ".." and none starts with '.'.
// The query (after '?') is split off first and decoded separately (parse_query); a fragment is refused.
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace lumigauss::view {

struct RequestTarget {
    std::string path;   // decoded, without the leading '/': "" for the root, "viewer.js", "a/b.js"
    std::string query;  // raw, without the '?'
};

inline constexpr std::size_t kMaxPathBytes = 1024;

// The decoded target, or nothing when the rules above refuse it.
std::optional<RequestTarget> parse_request_target(std::string_view target);

// %XX escapes decoded (and '+' as a space when plus_is_space). Nothing for a malformed escape or a decoded
// NUL byte.
std::optional<std::string> percent_decode(std::string_view text, bool plus_is_space);

// "a=1&b=x%20y" -> {a: "1", b: "x y"} (form encoding: '+' is a space). Nothing when an escape is malformed.
// A repeated key keeps its last value; a part without '=' has an empty value.
std::optional<std::map<std::string, std::string>> parse_query(std::string_view query);

}  // namespace lumigauss::view
