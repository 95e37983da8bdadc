#pragma once
// What the fuzz targets share: a scratch folder for the parsers that read paths, inputs that hold several
// files, and the rule that only lumigauss::Error may escape a parser.
#include <string>
#include <vector>

#include "fuzz_target.h"

namespace lumigauss::fuzz {

// A path in this process's scratch folder (created on first use, removed at exit).
std::string scratch_path(const std::string& name);

// Writes the bytes to the path (binary, replacing it).
void write_file(const std::string& path, Bytes bytes);
void write_file(const std::string& path, const std::string& bytes);

// The whole file as bytes.
std::string read_file(const std::string& path);

// Several files in one input: the parts joined by a separator line. Mutations that break a separator merge
// two parts, which the readers must survive too.
std::string join_parts(const std::vector<std::string>& parts);
std::vector<std::string> split_parts(Bytes input, std::size_t count);

// Runs the parser; lumigauss::Error is the expected way to refuse an input and is swallowed.
template <typename Parse>
void refuse_cleanly(Parse&& parse);

}  // namespace lumigauss::fuzz

#include "lumigauss/util/error.h"

template <typename Parse>
void lumigauss::fuzz::refuse_cleanly(Parse&& parse) {
    try {
        parse();
    } catch (const lumigauss::Error&) {
    }
}
