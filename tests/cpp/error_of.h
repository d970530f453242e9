#pragma once
// The one helper every test area uses to check error messages.
#include <functional>
#include <string>

#include "traces/common/error.h"

namespace rtsim::test {

/// The message of the rtsim::Error `fn` throws, or "" when it does not throw.
inline std::string error_of(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace rtsim::test
