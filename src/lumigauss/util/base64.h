#pragma once
// Standard base64 (RFC 4648, alphabet A-Z a-z 0-9 + /, '=' padding, no line breaks): how binary data rides
// inside text files (the self-contained viewer page carries its model this way).
#include <string>
#include <string_view>

namespace lumigauss {

std::string base64_encode(std::string_view bytes);

}  // namespace lumigauss
