#pragma once
// Reading a whole (small) file into memory: configs, JSON sidecars, camera lists.
#include <string>

namespace lumigauss {

// The file's bytes (binary mode, no newline translation). Throws Error naming the file if it cannot be opened
// or read.
std::string read_text_file(const std::string& path);

}  // namespace lumigauss
