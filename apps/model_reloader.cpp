#include "model_reloader.h"

#include <exception>
#include <filesystem>

namespace lumigauss::cli {

std::string model_files_fingerprint(const RunPaths& paths) {
    std::string fingerprint;
    for (const std::string& path : {paths.model, paths.lighting, paths.appearance, paths.sky}) {
        std::error_code ec;
        const auto time = std::filesystem::last_write_time(path, ec);
        const auto size = ec ? 0 : std::filesystem::file_size(path, ec);
        fingerprint += path + ':';
        fingerprint += ec ? std::string("-")
                          : std::to_string(time.time_since_epoch().count()) + ',' + std::to_string(size);
        fingerprint += ';';
    }
    return fingerprint;
}

ModelReloader::ModelReloader(RunPaths paths, std::string loaded, view::ViewerSite& site, Loader load,
                             std::function<void(const std::string&)> report, std::chrono::milliseconds period)
    : paths_(std::move(paths)),
      loaded_(std::move(loaded)),
      site_(site),
      load_(std::move(load)),
      report_(std::move(report)),
      period_(period),
      thread_([this] { watch(); }) {}

ModelReloader::~ModelReloader() {
    {
        const std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void ModelReloader::watch() {
    std::string loaded = loaded_, failed;
    std::unique_lock lock(mutex_);
    while (!wake_.wait_for(lock, period_, [this] { return stop_; })) {
        const std::string now = model_files_fingerprint(paths_);
        if (now == loaded || now == failed) continue;
        lock.unlock();
        try {
            auto [payload, scene] = load_();
            site_.replace(std::move(payload), std::move(scene));
            loaded = now;
            report_("newer model files in " + paths_.dir + ": reloaded (version " +
                    std::to_string(site_.version()) + "); open pages follow");
        } catch (const std::exception& e) {  // Error, and what libraries throw (bad_alloc, JSON, files)
            failed = now;
            report_(
                std::string("could not reload (keeping the current model until the files change again): ") +
                e.what());
        }
        lock.lock();
    }
}

}  // namespace lumigauss::cli
