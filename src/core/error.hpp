#pragma once
#include <stdexcept>
#include <string>

namespace ibrod {

/// Invalid user input (config key, value, file): the message names the key, the value and what
/// is allowed. The CLI prints it and exits with status 2.
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A run that cannot go on (non-finite state, I/O failure): the CLI prints it and exits with 3.
struct RunError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace ibrod
