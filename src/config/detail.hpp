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

/// A user-supplied text as messages echo it: control characters shown as \n, \t, \xNN, and
/// cut to `max` bytes with "…" (a 1 MB value must not make a 1 MB message).
inline std::string echo(const std::string& v, std::size_t max = 80) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (out.size() >= max) return out + "…";
    const unsigned char ch = static_cast<unsigned char>(v[i]);
    if (ch == '\n')
      out += "\\n";
    else if (ch == '\t')
      out += "\\t";
    else if (ch < 0x20 || ch == 0x7f) {
      static const char hex[] = "0123456789abcdef";
      out += std::string("\\x") + hex[ch >> 4] + hex[ch & 15];
    } else
      out += char(ch);
  }
  return out;
}

/// Throws ConfigError naming the key, its value (echoed, capped) and what is allowed.
[[noreturn]] inline void bad(const std::string& key, const std::string& value,
                             const std::string& allowed) {
  throw ConfigError("config: " + echo(key) + " = " + echo(value) + " is invalid: expected " +
                    allowed);
}

}  // namespace ibrod::config::detail
