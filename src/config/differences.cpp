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
