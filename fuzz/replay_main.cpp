// The fuzz targets without libFuzzer (any compiler): a target's seeds, any files given, and then seeded
// random mutations of them, each parsed once. CTest runs every target this way on each build, so the
// ASan/UBSan suite fuzzes too; scripts/fuzz.sh runs the coverage-guided libFuzzer build for longer.
//
//   lumigauss_fuzz TARGET [--mutations N] [--seed S] [FILE|DIR ...]
//   lumigauss_fuzz --list
//
// Each input is written to NAME.last-input before it is parsed: after a crash, that file reproduces it.
// Memory is capped (an allocation a tiny input should never need fails, and the target with it), and each
// input has 10 s.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz_support.h"

#if defined(__SANITIZE_ADDRESS__)
#define LUMIGAUSS_FUZZ_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LUMIGAUSS_FUZZ_ASAN 1
#endif
#endif

#ifdef LUMIGAUSS_FUZZ_ASAN
// Under ASan the cap is the allocator's: one allocation over 2 GiB is a reported error, not a null.
extern "C" const char* __asan_default_options() {
    return "allocator_may_return_null=0:max_allocation_size_mb=2048";
}
#endif

namespace {

using namespace lumigauss::fuzz;

// xorshift64*: the same mutations on every machine for a given --seed.
struct Random {
    std::uint64_t state;
    std::uint64_t next() {
        state ^= state >> 12, state ^= state << 25, state ^= state >> 27;
        return state * 0x2545F4914F6CDD1DULL;
    }
    std::size_t below(std::size_t n) { return n == 0 ? 0 : std::size_t(next() % n); }
};

// Numbers that break parsers: huge, negative, zero, not finite, overflowing.
const char* const kNastyNumbers[] = {
    "0",          "-1",     "4294967297",          "1e400", "nan", "-inf", "99999999999999999999",
    "2147483647", "1e-400", "18446744073709551615"};

void mutate_once(std::string& s, Random& r) {
    const std::size_t n = s.size();
    switch (r.below(8)) {
        case 0:  // flip a bit
            if (n) s[r.below(n)] ^= char(1u << r.below(8));
            break;
        case 1: {  // an interesting byte
            const char bytes[] = {0, char(0xff), char(0x7f), char(0x80), '\n', ' ', '-', '9'};
            if (n) s[r.below(n)] = bytes[r.below(sizeof bytes)];
            break;
        }
        case 2:  // cut the end
            s.resize(r.below(n + 1));
            break;
        case 3:  // delete a range
            if (n) {
                const std::size_t at = r.below(n);
                s.erase(at, 1 + r.below(std::min<std::size_t>(n - at, 64)));
            }
            break;
        case 4: {  // duplicate a range
            if (!n) break;
            const std::size_t at = r.below(n), len = 1 + r.below(std::min<std::size_t>(n - at, 256));
            s.insert(r.below(n + 1), s.substr(at, len));
            break;
        }
        case 5: {  // random bytes
            std::string junk(1 + r.below(16), '\0');
            for (char& c : junk) c = char(r.next());
            s.insert(r.below(n + 1), junk);
            break;
        }
        case 6: {  // a number replaced by a nasty one
            const std::size_t at = n ? r.below(n) : 0;
            std::size_t begin = at;
            while (begin < n && !std::isdigit(static_cast<unsigned char>(s[begin]))) ++begin;
            std::size_t end = begin;
            while (end < n && (std::isdigit(static_cast<unsigned char>(s[end])) || s[end] == '.')) ++end;
            s.replace(std::min(begin, n), end - std::min(begin, n),
                      kNastyNumbers[r.below(std::size(kNastyNumbers))]);
            break;
        }
        default: {  // 4 bytes set to a large little-endian integer (binary counts and sizes)
            if (n < 4) break;
            const std::uint32_t values[] = {0xffffffffu, 0x7fffffffu, 0x10000000u, 0x80000000u, 0u};
            const std::uint32_t v = values[r.below(std::size(values))];
            std::memcpy(&s[r.below(n - 3)], &v, 4);
            break;
        }
    }
}

void parse_one(const FuzzTarget& target, const std::string& input, const std::string& keep_path) {
    write_file(keep_path, input);
    ::alarm(10);
    target.parse({reinterpret_cast<const std::uint8_t*>(input.data()), input.size()});
    ::alarm(0);
}

}  // namespace

int main(int argc, char** argv) {
#ifndef LUMIGAUSS_FUZZ_ASAN
    const rlimit cap{4ull << 30, 4ull << 30};  // address space: std::bad_alloc past it
    ::setrlimit(RLIMIT_AS, &cap);
#endif
    if (argc < 2 || std::string(argv[1]) == "--list") {
        std::printf("usage: lumigauss_fuzz TARGET [--mutations N] [--seed S] [FILE|DIR ...]\ntargets:");
        for (const FuzzTarget& t : registered_targets()) std::printf(" %s", t.name);
        std::printf("\n");
        return argc < 2 ? 2 : 0;
    }
    const FuzzTarget* found = find_target(argv[1]);
    if (found == nullptr) {
        std::fprintf(stderr, "lumigauss_fuzz: no target named %s (--list names them)\n", argv[1]);
        return 2;
    }
    const FuzzTarget& target = *found;
    long mutations = 2000;
    std::uint64_t seed = 1;
    std::vector<std::string> inputs = target.seeds();
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        if ((a == "--mutations" || a == "--seed") && i + 1 < argc) {
            const std::string v = argv[++i];
            if (a == "--mutations")
                mutations = std::stol(v);
            else
                seed = std::stoull(v);
        } else if (std::filesystem::is_directory(a)) {
            for (const auto& e : std::filesystem::directory_iterator(a))
                if (e.is_regular_file()) inputs.push_back(read_file(e.path().string()));
        } else {
            inputs.push_back(read_file(a));
        }
    }
    const std::string keep = std::string(target.name) + ".last-input";
    std::printf("%s: %zu inputs, %ld mutations (seed %llu); a crash leaves its input in %s\n", target.name,
                inputs.size(), mutations, static_cast<unsigned long long>(seed), keep.c_str());
    std::fflush(stdout);
    const auto t0 = std::chrono::steady_clock::now();
    for (const std::string& input : inputs) parse_one(target, input, keep);
    Random random{seed * 0x9E3779B97F4A7C15ULL + 1};
    for (long m = 0; m < mutations; ++m) {
        std::string input = inputs[random.below(inputs.size())];
        const std::size_t edits = 1 + random.below(4);
        for (std::size_t e = 0; e < edits; ++e) mutate_once(input, random);
        parse_one(target, input, keep);
    }
    std::filesystem::remove(keep);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%s: %zu inputs parsed in %.1f s, no finding\n", target.name,
                inputs.size() + std::size_t(mutations), s);
    return 0;
}
