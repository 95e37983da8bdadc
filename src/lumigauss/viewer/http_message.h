#pragma once
// The two halves of one HTTP/1.x exchange as the viewer's server handles it: the request head it parses
// (request line and header fields; GET and HEAD carry no body) and the response it writes (status line,
// Content-Type, Content-Length and a few fixed safety headers, then the body unless the request was HEAD).
// One request per connection: every response says "Connection: close".
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lumigauss::view {

struct HttpRequest {
    std::string method;                                        // as sent, case-sensitive ("GET", "HEAD", ...)
    std::string target;                                        // the raw request target ("/index.html?x=1")
    std::string version;                                       // "HTTP/1.0" or "HTTP/1.1"
    std::vector<std::pair<std::string, std::string>> headers;  // names lower-cased, values trimmed

    // The value of the first header called `name` (lower case), if any.
    std::optional<std::string> header(std::string_view name) const;
};

enum class HeadParse { Complete, Incomplete, Malformed };

// Parses the head of `data` (everything up to the first empty line). Incomplete while no empty line has
// arrived; Malformed for a request line that is not "METHOD SP TARGET SP HTTP/1.x", a header line without a
// colon or with a control byte, obsolete line folding, or a bare LF.
HeadParse parse_request_head(std::string_view data, HttpRequest& out);

struct HttpResponse {
    int status = 200;
    std::string content_type;
    std::string_view body;              // points into `owner` or into static storage
    std::shared_ptr<const void> owner;  // keeps the body alive while it is written
    std::vector<std::pair<std::string, std::string>> extra_headers;

    // A small text/plain response holding its own copy of `text`.
    static HttpResponse text(int status, std::string text);
    // A response whose body is shared (e.g. the model payload, built once, served many times).
    static HttpResponse shared(std::string content_type, std::shared_ptr<const std::string> bytes);
};

// "OK", "Not Found", ...; "Unknown" for a code this server never sends.
const char* reason_phrase(int status);

// Status line and headers, ending with the empty line. Content-Length is always the body's length, also for
// a HEAD request (whose body the caller then does not send).
std::string response_head(const HttpResponse& response);

}  // namespace lumigauss::view
