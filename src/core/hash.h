#pragma once
// Digests of text for caches and stamps (not for security): Fowler–Noll–Vo FNV-1a, 64 bits
// (offset basis and prime from the FNV specification, Fowler, Noll and Vo). The same text gives
// the same digest on every machine and in every run.

#include <cstdint>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace lamina {

/// FNV-1a of `s`, continuing from `h` (pass a previous digest to hash several pieces in turn).
inline std::uint64_t fnv1a(std::string_view s, std::uint64_t h = 0xcbf29ce484222325ull) {
    for (unsigned char c : s) {
        h ^= c;
        h *= 0x100000001b3ull;
    }
    return h;
}

/// The digest as 16 hexadecimal digits.
inline std::string digest_hex(std::uint64_t h) {
    return fmt::format("{:016x}", h);
}

}  // namespace lamina
