#pragma once
// A small HTTP/1.x server for the viewer: POSIX sockets, one thread per connection, one request per
// connection. It listens on 127.0.0.1 only (the loopback address, never INADDR_ANY), so no other machine can
// connect. It parses the request head and hands it to a handler; the handler decides what to serve (the
// server itself never touches the file system).
//
// Requests the server answers itself, before the handler sees them:
//   405 any method but GET and HEAD (with "Allow: GET, HEAD");
//   400 a malformed head (http_message.h), a GET/HEAD announcing a body (Content-Length > 0 or
//       Transfer-Encoding), an HTTP/1.1 request without Host, or a Host naming another host than 127.0.0.1
//       or localhost, any port (DNS rebinding: a web page elsewhere whose name resolves to 127.0.0.1 must
//       not read the model; an SSH tunnel to another local port must still work);
//   431 a head longer than max_request_bytes.
// A client has head_seconds (10) from its connection to send the whole request head, however it trickles in.
// At most 64 connections run at once; a new client past that takes the place of the oldest connection that is
// still waiting for its head, so idle or slow clients cannot starve a real one (only 64 connections all busy
// sending responses make a new one wait, closed unanswered).
#include <atomic>
#include <cstddef>
#include <functional>
#include <list>
#include <mutex>
#include <thread>

#include "lumigauss/viewer/http_message.h"

namespace lumigauss::view {

using HttpHandler = std::function<HttpResponse(const HttpRequest&)>;

struct HttpServerOptions {
    int port = 0;                           // 0: the system picks a free port
    std::size_t max_request_bytes = 16384;  // request line + headers
    int head_seconds = 10;                  // from accept to the end of the request head
};

class HttpServer {
  public:
    // Binds 127.0.0.1:port and listens. Throws Error naming the port when it is in use or cannot be bound.
    HttpServer(const HttpServerOptions& options, HttpHandler handler);
    ~HttpServer();
    HttpServer(const HttpServer&) = delete;
    HttpServer& operator=(const HttpServer&) = delete;

    int port() const { return port_; }  // the bound port (the chosen one for port 0)

    // Accepts and serves connections until stop(); returns after every connection has finished.
    void run();
    // Makes run() return. Async-signal-safe (one write() to a pipe): callable from a signal handler, a
    // request handler or any thread, before or during run().
    void stop() noexcept;

  private:
    struct Worker;
    void serve_connection(int fd, Worker& worker);
    void evict_oldest_waiting();
    HttpResponse respond(const HttpRequest& request) const;
    void reap_finished(bool all);

    HttpServerOptions options_;
    HttpHandler handler_;
    int listen_fd_ = -1;
    int wake_read_ = -1, wake_write_ = -1;  // stop() writes here; run() polls it
    int port_ = 0;

    struct Worker {
        std::thread thread;
        std::atomic<bool> done{false};
        int fd = -1;
        bool awaiting_head = true;  // guarded by waiting_mutex_: while true, fd is open and may be shut down
    };
    std::list<Worker> workers_;  // the list is touched by the run() thread only
    std::mutex waiting_mutex_;
};

}  // namespace lumigauss::view
