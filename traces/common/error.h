#pragma once
// rtsim::Error: the one exception type for bad input. Its message names the culprit
// (file, element, field or ray) so a user can fix the input without a debugger.
#include <stdexcept>
#include <string>

namespace rtsim {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// Throws rtsim::Error with the message when the condition is false.
void require(bool condition, const std::string& message);

}  // namespace rtsim
