#include "lumigauss/viewer/http_message.h"

#include <algorithm>
#include <cctype>

namespace lumigauss::view {
namespace {

bool is_token_char(char c) {
    if (std::isalnum(static_cast<unsigned char>(c))) return true;
    return std::string_view("!#$%&'*+-.^_`|~").find(c) != std::string_view::npos;
}

bool has_control_byte(std::string_view s) {
    return std::any_of(s.begin(), s.end(), [](char c) {
        const auto u = static_cast<unsigned char>(c);
        return (u < 0x20 && c != '\t') || u == 0x7f;
    });
}

// HTTP optional whitespace (RFC 9110 5.6.3): spaces and tabs only.
std::string_view trim_ows(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

bool parse_request_line(std::string_view line, HttpRequest& out) {
    const std::size_t sp1 = line.find(' ');
    if (sp1 == std::string_view::npos) return false;
    const std::size_t sp2 = line.find(' ', sp1 + 1);
    if (sp2 == std::string_view::npos || line.find(' ', sp2 + 1) != std::string_view::npos) return false;
    out.method = std::string(line.substr(0, sp1));
    out.target = std::string(line.substr(sp1 + 1, sp2 - sp1 - 1));
    out.version = std::string(line.substr(sp2 + 1));
    if (out.method.empty() || !std::all_of(out.method.begin(), out.method.end(), is_token_char)) return false;
    if (out.target.empty() || has_control_byte(out.target)) return false;
    return out.version == "HTTP/1.1" || out.version == "HTTP/1.0";
}

bool parse_header_line(std::string_view line, HttpRequest& out) {
    if (line.front() == ' ' || line.front() == '\t') return false;  // obsolete line folding
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos || colon == 0) return false;
    const std::string_view name = line.substr(0, colon);
    if (!std::all_of(name.begin(), name.end(), is_token_char)) return false;
    const std::string_view value = trim_ows(line.substr(colon + 1));
    if (has_control_byte(value)) return false;
    std::string lower(name);
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    out.headers.emplace_back(std::move(lower), std::string(value));
    return true;
}

}  // namespace

std::optional<std::string> HttpRequest::header(std::string_view name) const {
    for (const auto& [k, v] : headers)
        if (k == name) return v;
    return std::nullopt;
}

HeadParse parse_request_head(std::string_view data, HttpRequest& out) {
    const std::size_t end = data.find("\r\n\r\n");
    if (end == std::string_view::npos) {
        // A bare LF line ending can never complete the head: refuse it early rather than wait for more.
        const std::size_t lf = data.find('\n');
        if (lf != std::string_view::npos && (lf == 0 || data[lf - 1] != '\r')) return HeadParse::Malformed;
        return HeadParse::Incomplete;
    }
    out = HttpRequest{};
    const std::string_view head = data.substr(0, end);
    std::size_t start = 0;
    bool first = true;
    while (start <= head.size()) {
        const std::size_t eol = std::min(head.find("\r\n", start), head.size());
        const std::string_view line = head.substr(start, eol - start);
        if (line.empty() || line.find('\n') != std::string_view::npos ||
            line.find('\r') != std::string_view::npos)
            return HeadParse::Malformed;
        if (!(first ? parse_request_line(line, out) : parse_header_line(line, out)))
            return HeadParse::Malformed;
        first = false;
        start = eol + 2;
    }
    return HeadParse::Complete;
}

HttpResponse HttpResponse::text(int status, std::string text) {
    auto bytes = std::make_shared<const std::string>(std::move(text));
    HttpResponse r = shared("text/plain; charset=utf-8", bytes);
    r.status = status;
    return r;
}

HttpResponse HttpResponse::shared(std::string content_type, std::shared_ptr<const std::string> bytes) {
    HttpResponse r;
    r.content_type = std::move(content_type);
    r.body = *bytes;
    r.owner = std::move(bytes);
    return r;
}

const char* reason_phrase(int status) {
    switch (status) {
        case 200:
            return "OK";
        case 400:
            return "Bad Request";
        case 403:
            return "Forbidden";
        case 404:
            return "Not Found";
        case 405:
            return "Method Not Allowed";
        case 413:
            return "Content Too Large";
        case 414:
            return "URI Too Long";
        case 431:
            return "Request Header Fields Too Large";
        case 500:
            return "Internal Server Error";
        case 503:
            return "Service Unavailable";
        default:
            return "Unknown";
    }
}

std::string response_head(const HttpResponse& r) {
    std::string h = "HTTP/1.1 " + std::to_string(r.status) + " " + reason_phrase(r.status) + "\r\n";
    if (!r.content_type.empty()) h += "Content-Type: " + r.content_type + "\r\n";
    h += "Content-Length: " + std::to_string(r.body.size()) + "\r\n";
    // Nothing is cached (a restarted server may serve another model under the same names), nothing is
    // sniffed into another type, and no other site may frame the page.
    h += "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\n";
    h += "Referrer-Policy: no-referrer\r\n";
    for (const auto& [k, v] : r.extra_headers) h += k + ": " + v + "\r\n";
    h += "Connection: close\r\n\r\n";
    return h;
}

}  // namespace lumigauss::view
