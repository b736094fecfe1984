#include <sstream>
#include <string>

#include "config/config.hpp"
#include "core/error.hpp"

namespace ibrod::config {

std::string config_differences(const std::string& old_toml, const Config& now,
                               const std::string& source) {
  Config old;
  try {
    apply_toml(old, old_toml, source);
  } catch (const ConfigError& e) {
    return std::string("the checkpoint's configuration cannot be read by this ibrod (") + e.what() +
           ")";
  }
  std::istringstream a(describe(old)), b(describe(now));
  std::string la, lb, out;
  auto strip = [](const std::string& l) { return l.substr(0, l.find(" #")); };
  while (std::getline(a, la) && std::getline(b, lb)) {
    la = strip(la);
    lb = strip(lb);
    while (!la.empty() && la.back() == ' ') la.pop_back();
    while (!lb.empty() && lb.back() == ' ') lb.pop_back();
    if (la == lb) continue;
    const auto eq = la.find(" = ");
    out += (out.empty() ? "" : "; ") + la.substr(0, eq) + ": " + la.substr(eq + 3) + " → " +
           lb.substr(lb.find(" = ") + 3);
  }
  // [[rods]] keys one side has and the other not (their lines come last)
  auto rest = [&](std::istringstream& in, std::string line, bool old_side) {
    while (!line.empty()) {
      line = strip(line);
      while (!line.empty() && line.back() == ' ') line.pop_back();
      const auto eq = line.find(" = ");
      out += (out.empty() ? "" : "; ") + line.substr(0, eq) + ": " +
             (old_side ? line.substr(eq + 3) + " → (none)" : "(none) → " + line.substr(eq + 3));
      if (!std::getline(in, line)) break;
    }
  };
  if (a && !la.empty() && b.eof()) rest(a, la, true);
  if (b && std::getline(b, lb)) rest(b, lb, false);
  return out;
}

bool only_end_time_extended(const std::string& old_toml, const Config& now,
                            const std::string& source) {
  Config old;
  try {
    apply_toml(old, old_toml, source);
  } catch (const ConfigError&) {
    return false;
  }
  if (!(now.time_t_end_us > old.time_t_end_us)) return false;
  old.time_t_end_us = now.time_t_end_us;
  return describe(old) == describe(now);
}

}  // namespace ibrod::config
