#include "lumigauss/viewer/http_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

#include "lumigauss/util/error.h"

namespace lumigauss::view {
namespace {

constexpr int kMaxConnections = 64;
constexpr int kIdleSeconds = 10;

std::string errno_text() {
    return std::strerror(errno);
}

void set_timeouts(int fd) {
    timeval tv{};
    tv.tv_sec = kIdleSeconds;
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
}

bool send_all(int fd, std::string_view bytes) {
    while (!bytes.empty()) {
        const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        bytes.remove_prefix(std::size_t(n));
    }
    return true;
}

// Half-closes and drains what the client still sends (briefly), so that the kernel does not answer unread
// request bytes with a reset that could destroy the response before the client has read it.
void close_gracefully(int fd) {
    ::shutdown(fd, SHUT_WR);
    timeval tv{0, 200000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    char buf[4096];
    for (int i = 0; i < 16 && ::recv(fd, buf, sizeof buf, 0) > 0; ++i) {
    }
    ::close(fd);
}

int bind_loopback(int port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) throw Error("view: cannot create a socket: " + errno_text());
    const int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);  // restart at once after a stop
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // 127.0.0.1 only, never other interfaces
    if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        const int err = errno;
        ::close(fd);
        if (err == EADDRINUSE)
            throw Error(
                "view: port " + std::to_string(port) +
                " on 127.0.0.1 is already in use: choose another with --port, or --port 0 for a free one");
        throw Error("view: cannot bind 127.0.0.1:" + std::to_string(port) + ": " + std::strerror(err));
    }
    if (::listen(fd, 64) != 0) {
        const int err = errno;
        ::close(fd);
        throw Error("view: cannot listen on 127.0.0.1:" + std::to_string(port) + ": " + std::strerror(err));
    }
    return fd;
}

int bound_port(int fd) {
    sockaddr_in addr{};
    socklen_t len = sizeof addr;
    if (::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0)
        throw Error("view: cannot read the bound port: " + errno_text());
    return ntohs(addr.sin_port);
}

enum class Received { Head, Malformed, TooLarge, Gone };

// Reads until the request head is complete, malformed or longer than max_bytes, or the client is gone or
// past the deadline (a client trickling a header line every few seconds used to hold its thread forever).
Received receive_head(int fd, std::size_t max_bytes, std::chrono::steady_clock::time_point deadline,
                      HttpRequest& request) {
    std::string data;
    char buf[8192];
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) return Received::Gone;
        pollfd p{fd, POLLIN, 0};
        const int ready = ::poll(&p, 1, int(left.count()));
        if (ready < 0 && errno == EINTR) continue;
        if (ready <= 0) return Received::Gone;
        const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return Received::Gone;
        data.append(buf, std::size_t(n));
        const HeadParse state = parse_request_head(data, request);
        const std::size_t head_end = data.find("\r\n\r\n");
        const std::size_t head_bytes = head_end == std::string::npos ? data.size() : head_end + 4;
        if (head_bytes > max_bytes) return Received::TooLarge;
        if (state == HeadParse::Malformed) return Received::Malformed;
        if (state == HeadParse::Complete) return Received::Head;
    }
}

// A Host header must name the loopback host: 127.0.0.1 or localhost. Any port, so that an SSH tunnel
// (ssh -L 9000:127.0.0.1:8080) works; the name is what defeats DNS rebinding.
bool host_allowed(std::string_view host) {
    const std::size_t colon = host.rfind(':');
    const std::string_view name = host.substr(0, colon);
    const std::string_view port = colon == std::string_view::npos ? "" : host.substr(colon + 1);
    const bool digits = std::all_of(port.begin(), port.end(), [](char c) { return c >= '0' && c <= '9'; });
    return (name == "127.0.0.1" || name == "localhost") && digits;
}

}  // namespace

HttpServer::HttpServer(const HttpServerOptions& options, HttpHandler handler)
    : options_(options), handler_(std::move(handler)) {
    if (options.port < 0 || options.port > 65535)
        throw Error("view: --port " + std::to_string(options.port) + " is not a TCP port (0..65535)");
    int pipe_fds[2];
    if (::pipe2(pipe_fds, O_CLOEXEC | O_NONBLOCK) != 0)
        throw Error("view: cannot create a pipe: " + errno_text());
    wake_read_ = pipe_fds[0], wake_write_ = pipe_fds[1];
    try {
        listen_fd_ = bind_loopback(options.port);
        port_ = bound_port(listen_fd_);
    } catch (...) {
        ::close(wake_read_), ::close(wake_write_);
        if (listen_fd_ >= 0) ::close(listen_fd_);
        throw;
    }
}

HttpServer::~HttpServer() {
    stop();
    reap_finished(true);
    ::close(listen_fd_);
    ::close(wake_read_);
    ::close(wake_write_);
}

void HttpServer::stop() noexcept {
    const char byte = 1;
    [[maybe_unused]] const ssize_t n = ::write(wake_write_, &byte, 1);  // a full pipe is already a stop
}

void HttpServer::reap_finished(bool all) {
    for (auto it = workers_.begin(); it != workers_.end();) {
        if (all || it->done.load()) {
            it->thread.join();
            it = workers_.erase(it);
        } else {
            ++it;
        }
    }
}

void HttpServer::run() {
    for (;;) {
        pollfd fds[2] = {{listen_fd_, POLLIN, 0}, {wake_read_, POLLIN, 0}};
        const int ready = ::poll(fds, 2, 1000);
        if (ready < 0 && errno != EINTR) throw Error("view: poll failed: " + errno_text());
        reap_finished(false);
        if (ready <= 0) continue;
        if (fds[1].revents != 0) break;
        if ((fds[0].revents & POLLIN) == 0) continue;
        const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
        if (fd < 0) continue;  // the client gave up already, or a transient shortage: keep serving
        if (workers_.size() >= std::size_t(kMaxConnections)) {
            evict_oldest_waiting();
            reap_finished(false);
            // Every connection busy with a response: a real overload, the new client is turned away.
            if (workers_.size() >= std::size_t(kMaxConnections) + 8) {
                ::close(fd);
                continue;
            }
        }
        Worker& w = workers_.emplace_back();
        w.fd = fd;
        w.thread = std::thread([this, fd, &w] {
            serve_connection(fd, w);
            w.done.store(true);
        });
    }
    reap_finished(true);
}

// The oldest connection still waiting for its request head gives its place to a new client: shutting its
// socket down ends its recv at once, and its thread closes it. Workers are in accept order.
void HttpServer::evict_oldest_waiting() {
    const std::lock_guard<std::mutex> lock(waiting_mutex_);
    for (Worker& w : workers_)
        if (w.awaiting_head && !w.done.load()) {
            ::shutdown(w.fd, SHUT_RDWR);
            w.awaiting_head = false;
            return;
        }
}

void HttpServer::serve_connection(int fd, Worker& worker) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(options_.head_seconds);
    set_timeouts(fd);
    HttpRequest request;
    const Received got = receive_head(fd, options_.max_request_bytes, deadline, request);
    {
        const std::lock_guard<std::mutex> lock(waiting_mutex_);  // from here on nobody shuts fd down
        worker.awaiting_head = false;
    }
    if (got == Received::Gone) {  // closed, timed out, evicted or failed before a whole head arrived
        ::close(fd);
        return;
    }
    const HttpResponse response = got == Received::Head ? respond(request)
                                  : got == Received::TooLarge
                                      ? HttpResponse::text(431, "request head too large\n")
                                      : HttpResponse::text(400, "malformed request\n");
    const bool head_only = got == Received::Head && request.method == "HEAD";
    if (send_all(fd, response_head(response)) && !head_only) send_all(fd, response.body);
    close_gracefully(fd);
}

HttpResponse HttpServer::respond(const HttpRequest& request) const {
    if (request.method != "GET" && request.method != "HEAD") {
        HttpResponse r = HttpResponse::text(405, "only GET and HEAD are served\n");
        r.extra_headers.emplace_back("Allow", "GET, HEAD");
        return r;
    }
    const auto length = request.header("content-length");
    if (request.header("transfer-encoding") || (length && *length != "0"))
        return HttpResponse::text(400, "this server takes no request bodies\n");
    // One Host header only: with two, a proxy and this server could each read a different one.
    const auto hosts = std::count_if(request.headers.begin(), request.headers.end(),
                                     [](const auto& h) { return h.first == "host"; });
    if (hosts > 1) return HttpResponse::text(400, "several Host headers\n");
    const auto host = request.header("host");
    if (host ? !host_allowed(*host) : request.version != "HTTP/1.0")
        return HttpResponse::text(400, "unexpected Host header\n");
    try {
        return handler_(request);
    } catch (const std::exception& e) {
        return HttpResponse::text(500, std::string("internal error: ") + e.what() + "\n");
    }
}

}  // namespace lumigauss::view
