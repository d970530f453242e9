#pragma once
// Choices in the config tree: an enum with its names, parsed and validated once when a config is
// read (an unknown name is an error naming the key), compared as an enum everywhere else.
#include <array>
#include <cstddef>
#include <cstring>

namespace rtsim {

/// The names of an enum's values in value order: Choices<E, N>{"a", "b"} names E(0), E(1).
template <class E, size_t N>
struct Choices {
    std::array<const char*, N> names;

    const char* name(E value) const {
        const auto i = static_cast<size_t>(value);
        return i < N ? names[i] : "unknown";
    }
    /// True and *value set when `text` is one of the names.
    bool parse(const char* text, E* value) const {
        for (size_t i = 0; i < N; ++i)
            if (std::strcmp(text, names[i]) == 0) {
                *value = static_cast<E>(i);
                return true;
            }
        return false;
    }
};

}  // namespace rtsim
