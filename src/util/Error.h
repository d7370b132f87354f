// The one exception type vdbdag throws for bad input or impossible requests.
// Its message is a single line meant for the user ("FILE: what is wrong");
// the CLI prints it and exits non-zero.
#pragma once
#include <stdexcept>
#include <string>

namespace vdbdag {

struct Error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

} // namespace vdbdag
