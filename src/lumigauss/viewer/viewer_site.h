#pragma once
// The viewer's routes (the request handler of http_server.h). Everything served is in memory; a request
// can only name one of these, never a file:
//   /                 index.html
//   /NAME             an embedded asset of web/viewer/ (viewer_assets.h), with its Content-Type
//   /model.bin        the model payload (model_payload.h), application/octet-stream
//   /scene.json       lights, up axis, initial camera, extent (scene_info.h), application/json
//   /version          {"version": N}, N counting the models served (1, then +1 per replace()), not cached:
//                     the page polls it and reloads model.bin and scene.json when it grows (a running
//                     training run's newer snapshot)
//   /bench-report     only with a report path (the hidden `view --bench-report FILE`, for tests and
//                     bench/viewer_bench.sh): GET /bench-report?data=<URL-encoded JSON object> writes the
//                     object to FILE (atomically) and calls on_report (which stops the server); answered
//                     once, 404 otherwise.
// A target that url_path.h refuses gets 400; any other name 404.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "lumigauss/viewer/http_message.h"

namespace lumigauss::view {

struct ViewerSiteOptions {
    std::string bench_report_path;    // empty: no /bench-report route
    std::function<void()> on_report;  // called after a report is written
};

class ViewerSite {
  public:
    ViewerSite(std::string model_payload, std::string scene_json, ViewerSiteOptions options);
    // Thread-safe: the server calls it from one thread per connection.
    HttpResponse handle(const HttpRequest& request);
    // Serves another model from now on (version + 1). Thread-safe; responses already begun keep the old one.
    void replace(std::string model_payload, std::string scene_json);
    std::uint64_t version() const;

  private:
    HttpResponse bench_report(const std::string& query);

    mutable std::mutex mutex_;  // guards the three below
    std::shared_ptr<const std::string> model_, scene_;
    std::uint64_t version_ = 1;
    ViewerSiteOptions options_;
    std::atomic<bool> reported_{false};
};

}  // namespace lumigauss::view
