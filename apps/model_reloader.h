#pragma once
// `view` on a training run that is still running: every checkpoint writes a new snapshot of the model files
// (model.ply, lighting.lgmlp, appearance.json, sky.lgsky), and the viewer should show it. A thread looks at
// the files' modification times and sizes every `period`; when they change it loads the run again and hands
// the new model to the site, whose page polls /version and reloads (viewer/viewer_site.h). A snapshot that
// cannot be loaded (caught between two of its files, or damaged) leaves the current model and is retried
// when the files change again.
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "lumigauss/model/trained_run.h"
#include "lumigauss/viewer/viewer_site.h"

namespace lumigauss::cli {

// The files `paths` names, each with its modification time and size ("-" when missing), as one string.
std::string model_files_fingerprint(const RunPaths& paths);

class ModelReloader {
  public:
    // `load` reads the run again and returns the new payload and scene JSON (throws Error when it cannot);
    // `report` receives one line per reload or failure.
    using Loader = std::function<std::pair<std::string, std::string>()>;
    // `loaded`: model_files_fingerprint(paths) taken BEFORE the model the site serves was loaded, so that a
    // snapshot written while it loaded is not taken for the one being served.
    ModelReloader(RunPaths paths, std::string loaded, view::ViewerSite& site, Loader load,
                  std::function<void(const std::string&)> report,
                  std::chrono::milliseconds period = std::chrono::seconds(2));
    ~ModelReloader();  // stops and joins the thread
    ModelReloader(const ModelReloader&) = delete;
    ModelReloader& operator=(const ModelReloader&) = delete;

  private:
    void watch();

    RunPaths paths_;
    std::string loaded_;
    view::ViewerSite& site_;
    Loader load_;
    std::function<void(const std::string&)> report_;
    std::chrono::milliseconds period_;
    std::mutex mutex_;
    std::condition_variable wake_;
    bool stop_ = false;
    std::thread thread_;
};

}  // namespace lumigauss::cli
