#include "lumigauss/viewer/viewer_site.h"

#include <nlohmann/json.hpp>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/viewer/url_path.h"
#include "lumigauss/viewer/viewer_assets.h"

namespace lumigauss::view {

ViewerSite::ViewerSite(std::string model_payload, std::string scene_json, ViewerSiteOptions options)
    : model_(std::make_shared<const std::string>(std::move(model_payload))),
      scene_(std::make_shared<const std::string>(std::move(scene_json))),
      options_(std::move(options)) {}

void ViewerSite::replace(std::string model_payload, std::string scene_json) {
    auto model = std::make_shared<const std::string>(std::move(model_payload));
    auto scene = std::make_shared<const std::string>(std::move(scene_json));
    const std::lock_guard lock(mutex_);
    model_ = std::move(model);
    scene_ = std::move(scene);
    ++version_;
}

std::uint64_t ViewerSite::version() const {
    const std::lock_guard lock(mutex_);
    return version_;
}

HttpResponse ViewerSite::handle(const HttpRequest& request) {
    const auto target = parse_request_target(request.target);
    if (!target) return HttpResponse::text(400, "refused request target\n");
    const std::string& path = target->path;
    if (path == "model.bin" || path == "scene.json" || path == "version") {
        const std::lock_guard lock(mutex_);
        if (path == "model.bin") return HttpResponse::shared("application/octet-stream", model_);
        if (path == "scene.json") return HttpResponse::shared("application/json", scene_);
        // Every response says Cache-Control: no-store (http_message.h), so the page's polls see each version.
        return HttpResponse::shared(
            "application/json",
            std::make_shared<const std::string>("{\"version\": " + std::to_string(version_) + "}\n"));
    }
    // GET only: a HEAD must not have the side effect of writing the report.
    if (path == "bench-report" && !options_.bench_report_path.empty() && request.method == "GET")
        return bench_report(target->query);
    const std::string name = path.empty() ? "index.html" : path;
    if (const EmbeddedAsset* asset = find_viewer_asset(name)) {
        HttpResponse r;
        r.content_type = content_type_for(name);
        r.body = asset->bytes;  // static storage: no owner needed
        return r;
    }
    return HttpResponse::text(404, "not found\n");
}

HttpResponse ViewerSite::bench_report(const std::string& query) {
    const auto params = parse_query(query);
    if (!params || !params->contains("data"))
        return HttpResponse::text(400, "bench-report needs ?data=JSON\n");
    const nlohmann::json report = nlohmann::json::parse(params->at("data"), nullptr, false);
    if (report.is_discarded() || !report.is_object())
        return HttpResponse::text(400, "bench-report: data is not a JSON object\n");
    if (reported_.exchange(true)) return HttpResponse::text(404, "a report was already received\n");
    write_file_atomically(options_.bench_report_path, report.dump(2) + "\n");
    if (options_.on_report) options_.on_report();
    return HttpResponse::text(200, "report written\n");
}

}  // namespace lumigauss::view
