// viewer/http_server.h + viewer/viewer_site.h: the viewer's server listens on 127.0.0.1 only, serves exactly
// the embedded assets and the generated payloads with the right types, refuses traversal attempts and any
// method but GET/HEAD, and stops cleanly.
#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <cctype>
#include <chrono>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>

#include "lumigauss/util/error.h"
#include "lumigauss/viewer/http_server.h"
#include "lumigauss/viewer/model_payload.h"
#include "lumigauss/viewer/scene_info.h"
#include "lumigauss/viewer/viewer_assets.h"
#include "lumigauss/viewer/viewer_site.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss::view {
namespace {

struct RawResponse {
    int status = 0;                              // 0: no answer (connection closed without a status line)
    std::map<std::string, std::string> headers;  // lower-case names
    std::string body;

    std::string header(const std::string& name) const {
        const auto it = headers.find(name);
        return it == headers.end() ? "" : it->second;
    }
};

int connect_to(in_addr_t address, int port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(std::uint16_t(port));
    addr.sin_addr.s_addr = address;
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
}

// Sends `request` as is and reads the whole answer (the server closes every connection).
RawResponse exchange(int port, const std::string& request) {
    const int fd = connect_to(htonl(INADDR_LOOPBACK), port);
    if (fd < 0) return {};
    ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
    std::string data;
    char buf[65536];
    for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) data.append(buf, std::size_t(n));
    ::close(fd);
    RawResponse r;
    const std::size_t end = data.find("\r\n\r\n");
    if (data.rfind("HTTP/1.1 ", 0) != 0 || end == std::string::npos) return r;
    r.status = std::stoi(data.substr(9, 3));
    std::istringstream head(data.substr(0, end));
    std::string line;
    std::getline(head, line);
    while (std::getline(head, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const std::size_t colon = line.find(':');
        std::string name = line.substr(0, colon);
        for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
        r.headers[name] = line.substr(colon + 2);
    }
    r.body = data.substr(end + 4);
    return r;
}

std::string get(const std::string& target, int port, const std::string& method = "GET") {
    return method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n\r\n";
}

// A server with a small model in a thread, for the duration of a test.
class ViewServerTest : public ::testing::Test {
  protected:
    void start(ViewerSiteOptions options = {}, std::size_t max_request = 16384, int head_seconds = 10) {
        const Camera cam = testing::test_camera();
        TrainedRun run =
            relight_test::in_memory_run(relight_test::random_model(cam, 3, 25), {"a.png", "b.png"});
        payload_ = encode_model_payload(run.model);
        scene_ = scene_json(describe_scene(run, {}, {0, 0, 1}, std::nullopt));
        site_ = std::make_unique<ViewerSite>(payload_, scene_, std::move(options));
        HttpServerOptions so;
        so.max_request_bytes = max_request;
        so.head_seconds = head_seconds;
        server_ = std::make_unique<HttpServer>(so, [this](const HttpRequest& r) { return site_->handle(r); });
        thread_ = std::thread([this] { server_->run(); });
    }
    void TearDown() override {
        if (server_) server_->stop();
        if (thread_.joinable()) thread_.join();
    }
    int port() const { return server_->port(); }
    RawResponse fetch(const std::string& target, const std::string& method = "GET") {
        return exchange(port(), get(target, port(), method));
    }

    std::string payload_, scene_;
    std::unique_ptr<ViewerSite> site_;
    std::unique_ptr<HttpServer> server_;
    std::thread thread_;
};

// The listening socket of `port` in /proc/net/tcp (Linux): its local address in the kernel's hex notation,
// or "" when not found.
std::string proc_listen_address(int port) {
    std::ifstream in("/proc/net/tcp");
    std::string line;
    char want[8];
    std::snprintf(want, sizeof want, ":%04X", port);
    while (std::getline(in, line)) {
        std::istringstream f(line);
        std::string slot, local, remote, state;
        f >> slot >> local >> remote >> state;
        if (state == "0A" && local.size() > 5 && local.substr(local.size() - 5) == want)
            return local.substr(0, local.size() - 5);
    }
    return "";
}

// 70 idle sockets (64 threads, each waiting 10 s for a head) made a normal GET / fail; now a new client takes
// the place of the oldest connection still waiting for its head.
TEST_F(ViewServerTest, IdleConnectionsDoNotStarveANewClient) {
    start();
    std::vector<int> idle;
    for (int i = 0; i < 70; ++i) idle.push_back(connect_to(htonl(INADDR_LOOPBACK), port()));
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(fetch("/").status, 200);
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
    for (const int fd : idle)
        if (fd >= 0) ::close(fd);
}

// A client trickling its head (a byte every 200 ms) held its thread as long as it liked: the head now has a
// deadline from the connection (1 s here), after which the server closes without answering.
TEST_F(ViewServerTest, ASlowHeadIsCutAtItsDeadline) {
    start({}, 16384, 1);
    const int fd = connect_to(htonl(INADDR_LOOPBACK), port());
    ASSERT_GE(fd, 0);
    const std::string head = get("/", port());
    const auto t0 = std::chrono::steady_clock::now();
    bool closed = false;
    for (std::size_t i = 0; i + 1 < head.size() && !closed; ++i) {
        if (::send(fd, &head[i], 1, MSG_NOSIGNAL) != 1) closed = true;
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 200) > 0) {
            char c;
            closed = ::recv(fd, &c, 1, 0) <= 0;
        }
    }
    EXPECT_TRUE(closed) << "the server waited for the whole slow head";
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_GT(seconds, 0.8);
    EXPECT_LT(seconds, 4.0);
    ::close(fd);
    EXPECT_EQ(fetch("/").status, 200);  // and the server goes on serving
}

TEST_F(ViewServerTest, ViewListensOnLoopbackOnly) {
    start();
    const std::string listen = proc_listen_address(port());
    if (!listen.empty()) {
        EXPECT_EQ(listen, "0100007F") << "bound to another address than 127.0.0.1";
    }
    const int fd = connect_to(htonl(INADDR_LOOPBACK), port());
    EXPECT_GE(fd, 0);
    if (fd >= 0) ::close(fd);
    // Every other IPv4 address of this machine is refused.
    ifaddrs* list = nullptr;
    ASSERT_EQ(::getifaddrs(&list), 0);
    int others = 0;
    for (ifaddrs* a = list; a; a = a->ifa_next) {
        if (!a->ifa_addr || a->ifa_addr->sa_family != AF_INET) continue;
        const in_addr_t ip = reinterpret_cast<sockaddr_in*>(a->ifa_addr)->sin_addr.s_addr;
        if ((ntohl(ip) >> 24) == 127) continue;
        ++others;
        const int other = connect_to(ip, port());
        EXPECT_LT(other, 0) << "reachable on " << a->ifa_name;
        if (other >= 0) ::close(other);
    }
    ::freeifaddrs(list);
    if (listen.empty() && others == 0) GTEST_SKIP() << "no /proc/net/tcp and no other interface to check";
}

TEST_F(ViewServerTest, ViewServesEveryAssetWithItsType) {
    start();
    ASSERT_NE(find_viewer_asset("index.html"), nullptr);
    ASSERT_NE(find_viewer_asset("viewer.js"), nullptr);
    ASSERT_NE(find_viewer_asset("sort_worker.js"), nullptr);
    for (const EmbeddedAsset& a : viewer_assets()) {
        const RawResponse r = fetch("/" + std::string(a.name));
        EXPECT_EQ(r.status, 200) << a.name;
        EXPECT_EQ(r.body, a.bytes) << a.name;
        EXPECT_EQ(r.header("content-length"), std::to_string(a.bytes.size())) << a.name;
        EXPECT_EQ(r.header("content-type"), content_type_for(a.name)) << a.name;
        EXPECT_EQ(r.header("x-content-type-options"), "nosniff");
        if (a.name.ends_with(".js")) {
            EXPECT_EQ(r.header("content-type"), "text/javascript; charset=utf-8");
        }
        if (a.name.ends_with(".html")) {
            EXPECT_EQ(r.header("content-type"), "text/html; charset=utf-8");
        }
    }
    const RawResponse root = fetch("/");
    EXPECT_EQ(root.status, 200);
    EXPECT_EQ(root.body, find_viewer_asset("index.html")->bytes);
    const RawResponse model = fetch("/model.bin");
    EXPECT_EQ(model.status, 200);
    EXPECT_EQ(model.header("content-type"), "application/octet-stream");
    EXPECT_EQ(model.body, payload_);
    const RawResponse scene = fetch("/scene.json");
    EXPECT_EQ(scene.header("content-type"), "application/json");
    EXPECT_EQ(scene.body, scene_);
    EXPECT_EQ(fetch("/missing.js").status, 404);
    EXPECT_EQ(fetch("/bench-report?data={}").status, 404) << "the report route exists only in bench mode";
}

TEST_F(ViewServerTest, ViewRefusesTraversalAttempts) {
    start();
    const std::string targets[] = {
        "/../etc/passwd",
        "/../../../../etc/passwd",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/%2E%2E%2Fetc%2Fpasswd",
        "/..%2f..%2fetc/passwd",
        "//etc/passwd",
        "/%2fetc%2fpasswd",
        "/etc/passwd",
        "/index.html%00.js",
        "/.%2e/index.html",
        "/%252e%252e/etc/passwd",
        "/..\\..\\etc\\passwd",
        "/./index.html",
        "/web/viewer/index.html",
        "/proc/self/environ",
        "http://127.0.0.1/etc/passwd",
    };
    for (const std::string& t : targets) {
        const RawResponse r = fetch(t);
        EXPECT_TRUE(r.status == 400 || r.status == 404) << t << " -> " << r.status;
        EXPECT_EQ(r.body.find("root:"), std::string::npos) << t;
    }
    // A raw NUL in the request line is malformed.
    std::string with_nul = "GET /index.html";
    with_nul += '\0';
    with_nul += ".js HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port()) + "\r\n\r\n";
    const RawResponse nul = exchange(port(), with_nul);
    EXPECT_EQ(nul.status, 400);
}

TEST_F(ViewServerTest, ViewAnswersOnlyGetAndHead) {
    start();
    for (const std::string m : {"POST", "PUT", "DELETE", "PATCH", "OPTIONS", "TRACE", "FOO"}) {
        const RawResponse r = fetch("/index.html", m);
        EXPECT_EQ(r.status, 405) << m;
        EXPECT_EQ(r.header("allow"), "GET, HEAD") << m;
    }
    const RawResponse post = exchange(port(), "POST / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port()) +
                                                  "\r\nContent-Length: 5\r\n\r\nhello");
    EXPECT_EQ(post.status, 405);
    const RawResponse head = fetch("/viewer.js", "HEAD");
    EXPECT_EQ(head.status, 200);
    EXPECT_TRUE(head.body.empty());
    EXPECT_EQ(head.header("content-length"), std::to_string(find_viewer_asset("viewer.js")->bytes.size()));
}

TEST_F(ViewServerTest, ViewRejectsMalformedForeignAndOversizedRequests) {
    start();
    EXPECT_EQ(exchange(port(), "GARBAGE\r\n\r\n").status, 400);
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.1\nHost: x\n\n").status, 400);
    EXPECT_EQ(exchange(port(), "GET / HTTP/2.0\r\n\r\n").status, 400);
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.1\r\n\r\n").status, 400) << "HTTP/1.1 needs a Host";
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: evil.example\r\n\r\n").status, 400)
        << "a second Host header";
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.1\r\nHost: evil.example:" + std::to_string(port()) + "\r\n\r\n")
                  .status,
              400)
        << "a page elsewhere rebinding its name to 127.0.0.1";
    EXPECT_EQ(
        exchange(port(), "GET / HTTP/1.1\r\nHost: localhost:" + std::to_string(port()) + "\r\n\r\n").status,
        200);
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.1\r\nHost: localhost:9000\r\n\r\n").status, 200)
        << "an SSH tunnel";
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.1\r\nHost: 127.0.0.1.evil.example\r\n\r\n").status, 400);
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.0\r\n\r\n").status, 200);
    EXPECT_EQ(exchange(port(), "GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port()) +
                                   "\r\nContent-Length: 3\r\n\r\nabc")
                  .status,
              400);
    EXPECT_EQ(fetch("/" + std::string(20000, 'a')).status, 431);
}

TEST(ViewHttpServer, ReportsAPortInUseAndStopsFromAnotherThread) {
    HttpServer first({}, [](const HttpRequest&) { return HttpResponse::text(200, "x"); });
    HttpServerOptions same;
    same.port = first.port();
    try {
        HttpServer second(same, [](const HttpRequest&) { return HttpResponse::text(200, "y"); });
        ADD_FAILURE() << "a second server bound the same port";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("already in use"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos) << e.what();
    }
    std::atomic<bool> returned{false};
    std::thread t([&] {
        first.run();
        returned = true;
    });
    EXPECT_EQ(exchange(first.port(), get("/", first.port())).status, 200);
    first.stop();
    t.join();
    EXPECT_TRUE(returned);
}

TEST_F(ViewServerTest, ViewBenchReportIsWrittenOnceThenStops) {
    testing::TempDir tmp("view_report");
    std::atomic<int> reports{0};
    ViewerSiteOptions o;
    o.bench_report_path = tmp / "report.json";
    o.on_report = [&] { ++reports; };
    start(std::move(o), 1 << 20);
    EXPECT_EQ(fetch("/bench-report?data=not-json").status, 400);
    EXPECT_EQ(fetch("/bench-report?data=%5B1%5D").status, 400) << "an array is not a report";
    EXPECT_EQ(fetch("/bench-report").status, 400);
    EXPECT_EQ(reports, 0);
    EXPECT_EQ(fetch("/bench-report?data=%7B%22frames%22%3A3%7D").status, 200);
    EXPECT_EQ(reports, 1);
    std::ifstream in(tmp / "report.json");
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_NE(text.str().find("\"frames\": 3"), std::string::npos) << text.str();
    EXPECT_EQ(fetch("/bench-report?data=%7B%7D").status, 404) << "only the first report counts";
    EXPECT_EQ(reports, 1);
}

}  // namespace
}  // namespace lumigauss::view
