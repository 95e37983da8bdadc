#pragma once
// Atomic file replacement: write everything to `path + ".tmp"`, then rename over `path`, so that a crash or a
// full disk never leaves a half-written image, model or checkpoint where a good one was.
#include <functional>
#include <string>

namespace lumigauss {

// The temporary name a writer of `path` uses.
std::string temp_path_for(const std::string& path);

// Calls `write(tmp)` to produce the file at the temporary path, then renames it to `path`. If `write` throws,
// the temporary file is removed and the exception propagates. Throws Error naming `path` if the rename fails.
void write_atomically(const std::string& path, const std::function<void(const std::string& tmp)>& write);

// Writes `content` to `path` atomically (binary mode, no newline translation).
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace lumigauss
