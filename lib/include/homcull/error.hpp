#pragma once
// The one exception type homcull's C++ libraries throw. Messages name the thing that is wrong
// (a file, an option, an object) and the problem, ready to show a user as they are.
// (There is no C ABI yet: a C wrapper would catch it at its boundary.) The command-line
// program turns an Error into exit code 1.
#include <stdexcept>
#include <string>

namespace homcull {

class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace homcull
