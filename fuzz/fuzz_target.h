#pragma once
// A fuzz target: one of the project's parsers or file readers fed arbitrary bytes. Each file in targets/
// defines one and registers it (LUMIGAUSS_FUZZ_TARGET). With libFuzzer (libfuzzer_main.cpp, clang,
// scripts/fuzz.sh) each target is its own executable; otherwise all of them are linked into one replay driver
// (replay_main.cpp: a target's seeds plus seeded random mutations, a CTest test per target on every build).
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

// Adds a target to the executable's list (at static initialisation); returns true.
bool register_target(const FuzzTarget& target);

// The targets linked into this executable, in registration order.
const std::vector<FuzzTarget>& registered_targets();

// The target of that name; nullptr if none.
const FuzzTarget* find_target(const std::string& name);

}  // namespace lumigauss::fuzz

// Registers the target NAME (a bare identifier) with its seeds and parse functions. Written once at the end
// of each file of targets/, at namespace scope.
#define LUMIGAUSS_FUZZ_TARGET(NAME, SEEDS, PARSE)                                               \
    namespace {                                                                                 \
    [[maybe_unused]] const bool registered_##NAME =                                             \
        ::lumigauss::fuzz::register_target(::lumigauss::fuzz::FuzzTarget{#NAME, SEEDS, PARSE}); \
    }
