#pragma once
// Named enums. Beside an enum E that is a setting or an option, enum_names(E{}) lists each value,
// its text and what it means, and enum_noun(E{}) names the kind of value ("a kernel"); both are
// found by argument-dependent lookup. Settings read and write the enum by these names
// (core/setting.h), so they are written once, beside the enum.

namespace lamina {

template <typename E>
struct EnumName {
    E value;
    const char* text;
    const char* meaning;
};

/// The text of `value` ("?" for a value the list lacks, which is a programming error).
template <typename E>
const char* enum_text(E value) {
    for (const auto& n : enum_names(E{}))
        if (n.value == value) return n.text;
    return "?";
}

}  // namespace lamina
