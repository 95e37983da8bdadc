#pragma once
// Each sub-command of the `lumigauss` tool lives in its own cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>

namespace lumigauss::cli {

void register_env(CLI::App& app);
void register_eval(CLI::App& app);
void register_export(CLI::App& app);
void register_fit_light(CLI::App& app);
void register_info(CLI::App& app);
void register_render(CLI::App& app);
void register_synth(CLI::App& app);
void register_train(CLI::App& app);
void register_view(CLI::App& app);

}  // namespace lumigauss::cli
