#pragma once
// Split files: one line per image, `filename;split` with split in {train, test, val, validation} (any case).
// A header line (first line whose split field is not a split name) is allowed; ',' or a tab may replace ';'.
#include <map>
#include <string>

#include "lumigauss/io/dataset.h"

namespace lumigauss {

// File name -> split. Throws Error naming the file and line for a malformed line, an unknown split or a
// file name listed twice.
std::map<std::string, Split> read_split_file(const std::string& path);

}  // namespace lumigauss
