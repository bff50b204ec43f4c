#pragma once
// Binary file writers' common step: a value's bytes appended to a buffer in the machine's order
// (little-endian on every machine lamina builds for, as the .npz and RGL tensor formats want).

#include <cstring>
#include <string>
#include <type_traits>

namespace lamina {

template <typename T>
void append_bytes(std::string& out, T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    out.append(b, sizeof(T));
}

}  // namespace lamina
