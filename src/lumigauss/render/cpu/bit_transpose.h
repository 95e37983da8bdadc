#pragma once
// Bit tricks for sorting groups of eight entries into the 32 block lists of a tile (internal to the CPU
// backend, tile_blocks.h): which entries of a group reach each block, and where the set bits of a byte are.
#include <array>
#include <cstdint>

namespace lumigauss::cpu {

// The 8x8 bit matrix in x (byte r, bit c) transposed: byte c, bit r of the result is byte r, bit c of x.
// Three rounds of swapping off-diagonal blocks (Hacker's Delight, section 7-3).
constexpr std::uint64_t transpose_bits_8x8(std::uint64_t x) {
    std::uint64_t t = (x ^ (x >> 7)) & 0x00AA00AA00AA00AAull;
    x = x ^ t ^ (t << 7);
    t = (x ^ (x >> 14)) & 0x0000CCCC0000CCCCull;
    x = x ^ t ^ (t << 14);
    t = (x ^ (x >> 28)) & 0x00000000F0F0F0F0ull;
    return x ^ t ^ (t << 28);
}

// For every byte value: the positions of its set bits, lowest first, one per 4-bit nibble (the rest zero).
inline constexpr std::array<std::uint32_t, 256> kSetBitPositions = [] {
    std::array<std::uint32_t, 256> table{};
    for (unsigned value = 0; value < 256; ++value) {
        int n = 0;
        for (unsigned bit = 0; bit < 8; ++bit)
            if (value >> bit & 1) table[value] |= bit << (4 * n++);
    }
    return table;
}();

}  // namespace lumigauss::cpu
