#pragma once
// Helpers shared by the config layer's files (not part of its interface).
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace ibrod::config::detail {

/// A number as the messages and `ibrod check` show it (12 significant digits).
inline std::string fmt(double v) {
  std::ostringstream os;
  os.precision(12);
  os << v;
  return os.str();
}

/// Throws ConfigError naming the key, its value and what is allowed.
[[noreturn]] inline void bad(const std::string& key, const std::string& value,
                             const std::string& allowed) {
  throw ConfigError("config: " + key + " = " + value + " is invalid: expected " + allowed);
}

}  // namespace ibrod::config::detail
