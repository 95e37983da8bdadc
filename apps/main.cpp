// The `lumigauss` command-line tool: one binary, one sub-command per job.
#include <cstdio>
#include <exception>

#include "commands.h"
#include "lumigauss/util/error.h"

int main(int argc, char** argv) {
    CLI::App app{"lumigauss: relightable 2D Gaussian surfels from photos under many lightings"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "lumigauss 0.1.0");
    lumigauss::cli::register_env(app);
    lumigauss::cli::register_eval(app);
    lumigauss::cli::register_export(app);
    lumigauss::cli::register_fit_light(app);
    lumigauss::cli::register_info(app);
    lumigauss::cli::register_render(app);
    lumigauss::cli::register_synth(app);
    lumigauss::cli::register_train(app);
    lumigauss::cli::register_view(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const lumigauss::Error& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "internal error: %s\n", e.what());
        return 2;
    }
    return 0;
}
