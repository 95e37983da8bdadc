#pragma once
// A fuzz target: one of the project's parsers or file readers fed arbitrary bytes. Each file in targets/
// defines one, and is linked either with libFuzzer (libfuzzer_main.cpp, clang, scripts/fuzz.sh) or with the
// replay driver (replay_main.cpp: its seeds plus seeded random mutations, as a CTest test on every build).
//
// The contract a target checks: the parser returns, or throws lumigauss::Error (a clear message naming the
// file). Anything else (a crash, a sanitizer report, another exception type, an allocation over the memory
// limit, a hang) is a finding.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace lumigauss::fuzz {

using Bytes = std::span<const std::uint8_t>;

struct FuzzTarget {
    const char* name;
    // Valid inputs written by the project's own writers: the corpus every run starts from.
    std::vector<std::string> (*seeds)();
    // Parses the bytes; throws only lumigauss::Error for bad input.
    void (*parse)(Bytes input);
};

// Defined by the one file of targets/ linked into the executable.
const FuzzTarget& fuzz_target();

}  // namespace lumigauss::fuzz
