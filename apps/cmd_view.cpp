// `lumigauss view SOURCE [--port P] [--light L ...]`: serves the real-time relighting viewer (web/viewer/,
// embedded in the binary) for a trained run or a bare relightable PLY on http://127.0.0.1:P/ until Ctrl-C,
// following the newer snapshots of a run that is still training (model_reloader.h).
// The page renders in WebGL2: orbit camera, environment from the training photos' learned lightings or an SH
// file, environment rotation, shadowed/unshadowed/albedo/normals/shadow views (src/lumigauss/viewer/).
#include <csignal>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/util/error.h"
#include "lumigauss/viewer/http_server.h"
#include "lumigauss/viewer/model_payload.h"
#include "lumigauss/viewer/scene_info.h"
#include "lumigauss/viewer/viewer_site.h"
#include "model_reloader.h"
#include "viewer_scene.h"

namespace lumigauss::cli {
namespace {

struct ViewOptions {
    std::string source, scene, camera_json, up = "auto", bench_report;
    bool quiet = false;
    std::vector<std::string> lights;
    int port = 8080;
};

// The server Ctrl-C stops. A plain pointer read by the signal handler: set before the handler is installed,
// cleared after it is removed.
view::HttpServer* g_server = nullptr;

extern "C" void on_stop_signal(int) {
    if (g_server) g_server->stop();  // async-signal-safe: one write() to a pipe
}

// Installs SIGINT/SIGTERM handlers for the lifetime of the object, restoring the previous ones after.
class StopSignals {
  public:
    explicit StopSignals(view::HttpServer& server) {
        g_server = &server;
        struct sigaction sa = {};
        sa.sa_handler = on_stop_signal;
        sigemptyset(&sa.sa_mask);
        sigaction(SIGINT, &sa, &old_int_);
        sigaction(SIGTERM, &sa, &old_term_);
    }
    ~StopSignals() {
        sigaction(SIGINT, &old_int_, nullptr);
        sigaction(SIGTERM, &old_term_, nullptr);
        g_server = nullptr;
    }
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;

  private:
    struct sigaction old_int_ = {};
    struct sigaction old_term_ = {};
};

void run_view(const ViewOptions& o) {
    const ViewerSceneOptions scene_options{o.source, o.scene, o.camera_json, o.up, o.lights};
    // The files' state before they are read: a snapshot written while they load is served next.
    const RunPaths watched = run_paths_of(o.source);
    const std::string fingerprint = model_files_fingerprint(watched);
    const TrainedRun run = load_run_or_ply(o.source);
    const view::ViewerScene scene = viewer_scene_for(run, scene_options);

    view::HttpServer* server_ptr = nullptr;
    view::ViewerSiteOptions site_options;
    site_options.bench_report_path = o.bench_report;
    site_options.on_report = [&server_ptr] {
        if (server_ptr) server_ptr->stop();
    };
    view::ViewerSite site(view::encode_model_payload(run.model), view::scene_json(scene), site_options);
    view::HttpServerOptions server_options;
    server_options.port = o.port;
    // The bench report travels in the query string of a GET: allow long request heads only then.
    server_options.max_request_bytes = o.bench_report.empty() ? 16384 : 8u << 20;
    view::HttpServer server(server_options, [&site](const view::HttpRequest& r) { return site.handle(r); });
    server_ptr = &server;
    StopSignals signals(server);
    // A running training run writes a newer snapshot with every checkpoint: the page follows it.
    const ModelReloader reloader(
        watched, fingerprint, site,
        [&scene_options] {
            const TrainedRun newer = load_run_or_ply(scene_options.source);
            return std::pair{view::encode_model_payload(newer.model),
                             view::scene_json(viewer_scene_for(newer, scene_options))};
        },
        [&o](const std::string& line) {
            if (!o.quiet) std::printf("view: %s\n", line.c_str());
            std::fflush(stdout);
        });
    if (!o.quiet)
        std::printf("view: %zu surfels, %zu lights, up %s\n", run.model.size(), scene.lights.size(),
                    up_axis_name(scene.up).c_str());
    std::printf("view: open http://127.0.0.1:%d/ (Ctrl-C to stop)\n", server.port());
    std::fflush(stdout);
    server.run();
    if (!o.quiet) std::printf("view: stopped\n");
}

}  // namespace

void register_view(CLI::App& app) {
    auto o = std::make_shared<ViewOptions>();
    CLI::App* cmd = app.add_subcommand(
        "view",
        "Serve the real-time relighting viewer (WebGL2) for a trained run or a relightable .ply on "
        "http://127.0.0.1:PORT/ (loopback only) until Ctrl-C");
    cmd->add_option("source", o->source,
                    "training run folder (model.ply, lighting.lgmlp, appearance.json) or a relightable .ply "
                    "(official LumiGauss layout)")
        ->required();
    cmd->add_option("--port", o->port, "TCP port on 127.0.0.1 (0: a free one; the URL is printed)")
        ->capture_default_str();
    cmd->add_option("--light", o->lights,
                    "extra lighting(s) offered first: a training photo's name, a .txt SH file (9 rows R G B) "
                    "or a panorama, as for `render --light` (repeatable)");
    cmd->add_option(
           "--up", o->up,
           "world up for orbiting and turning the environment: +z, -y, +y, +x, -x, -z, a vector "
           "X,Y,Z, or auto (the cameras' up: --camera, the scene, the run's training photos; +z for a "
           "bare PLY)")
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", o->quiet, "print only the address to open");
    cmd->add_option("--scene", o->scene,
                    "scene folder (COLMAP or NeRF-OSR): its first training view is the initial camera "
                    "(default: the scene the run was trained on, RUN/scene.json, if it is still there)");
    cmd->add_option("--camera", o->camera_json,
                    "camera JSON (as for `render --cameras FILE`): its first camera is the initial view");
    // Hidden (empty group): for the browser test and bench/viewer_bench.sh.
    cmd->add_option("--bench-report", o->bench_report,
                    "accept one GET /bench-report?data=JSON from the page, write it to FILE and exit")
        ->group("");
    cmd->callback([o] { run_view(*o); });
}

}  // namespace lumigauss::cli
