#include "lumigauss/io/text_file.h"

#include <fstream>
#include <sstream>

#include "lumigauss/util/error.h"

namespace lumigauss {

std::string read_text_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail_in_file(path, "cannot open");
    std::stringstream text;
    text << in.rdbuf();
    if (in.bad()) fail_in_file(path, "read failed");
    return text.str();
}

}  // namespace lumigauss
