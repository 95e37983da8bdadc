// The viewer's HTTP request head parser and URL target decoder (viewer/http_message.h, viewer/url_path.h):
// the bytes a local client sends.
#include "fuzz_support.h"
#include "lumigauss/viewer/http_message.h"
#include "lumigauss/viewer/url_path.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    return {"GET / HTTP/1.1\r\nHost: 127.0.0.1:8080\r\n\r\n",
            "GET /api/render?view=train_0001.png&light=sky%2000&w=320 HTTP/1.1\r\nHost: localhost\r\n"
            "Connection: keep-alive\r\nAccept: */*\r\n\r\n",
            "GET /assets/%2e%2e/x+y.js HTTP/1.0\r\n\r\n"};
}

void parse(Bytes input) {
    using namespace lumigauss::view;
    const std::string_view data(reinterpret_cast<const char*>(input.data()), input.size());
    refuse_cleanly([&] {
        HttpRequest request;
        if (parse_request_head(data, request) == HeadParse::Complete) {
            (void)request.header("host");
            if (const auto target = parse_request_target(request.target)) (void)parse_query(target->query);
        }
        (void)parse_request_target(data);
        (void)percent_decode(data, true);
        (void)parse_query(data);
    });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(http_request, seeds, parse)

}  // namespace lumigauss::fuzz
