#pragma once
#include <stdexcept>
#include <string>

namespace rend {

/// A problem with the user's input: the message already names file:line:column, the key, what
/// was expected, what was found and the fix. main() prints it and exits with status 2.
class SceneError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace rend
