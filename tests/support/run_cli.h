#pragma once
// Runs the `lumigauss` binary (LUMIGAUSS_BINARY, set by tests/CMakeLists.txt) for the CLI tests, capturing
// stdout and stderr through a file in the test's temporary folder.
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "support/temp_dir.h"

namespace lumigauss::testing {

struct CommandResult {
    int exit_code = -1;  // -1 when the process did not exit normally
    std::string output;  // stdout and stderr together
};

// Single-quoted for the shell (test paths hold no single quotes).
inline std::string shell_quoted(const std::string& s) {
    return "'" + s + "'";
}

// Runs `lumigauss ARGS` (ARGS already quoted as needed); `env` is put in front, e.g. "PATH=...:$PATH".
inline CommandResult run_lumigauss(const std::string& args, const TempDir& tmp, const std::string& env = "") {
    const std::string out = tmp.sub("output.txt");
    const std::string command = (env.empty() ? "" : env + " ") + shell_quoted(LUMIGAUSS_BINARY) + " " + args +
                                " > " + shell_quoted(out) + " 2>&1";
    const int status = std::system(command.c_str());
    std::ifstream in(out, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text.str()};
}

}  // namespace lumigauss::testing
