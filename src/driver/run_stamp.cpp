#include "driver/run_stamp.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <random>
#include <sstream>

#include "core/text_file.hpp"
#include "io/checkpoint.hpp"

namespace ibrod::driver {

namespace {
constexpr const char* kIdLine = "# run_id = ";
constexpr const char* kInputLine = "# input ";
}  // namespace

std::string new_run_id() {
  std::random_device rd;
  std::uint64_t x = (std::uint64_t(rd()) << 32) ^ rd();
  x ^= std::uint64_t(std::chrono::system_clock::now().time_since_epoch().count());
  x ^= std::uint64_t(::getpid()) << 17;
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(x));
  return buf;
}

std::vector<std::pair<std::string, std::string>> input_checksums(const config::Config& c) {
  std::vector<std::pair<std::string, std::string>> out;
  const auto add = [&](const std::string& key, const std::string& path) {
    if (path.empty()) return;
    std::string sum = "unreadable";
    if (const auto text = try_read_text_file(path)) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "%08x", io::crc32(text->data(), text->size()));
      sum = buf;
    }
    out.emplace_back(key, "\"" + path + "\" crc32 " + sum);
  };
  for (const config::RodConfig& rc : config::rod_configs(c)) {
    add(rc.key("intrinsic_file"), rc.keys.rod_intrinsic_file);
    add(rc.key("moduli_file"), rc.keys.rod_moduli_file);
  }
  return out;
}

std::string stamp_text(const RunStamp& s) {
  std::string out =
      "\n# written by the run, not keys: its id and the CRC-32 of each input file (--resume "
      "checks them)\n";
  if (!s.run_id.empty()) out += kIdLine + s.run_id + "\n";
  for (const auto& [key, sum] : s.inputs) out += kInputLine + key + " = " + sum + "\n";
  return out;
}

RunStamp read_stamp(const std::string& config_text) {
  RunStamp s;
  std::istringstream in(config_text);
  std::string line;
  const std::string id = kIdLine, input = kInputLine;
  while (std::getline(in, line)) {
    if (line.rfind(id, 0) == 0) s.run_id = line.substr(id.size());
    if (line.rfind(input, 0) == 0) {
      const std::string rest = line.substr(input.size());
      const auto eq = rest.find(" = ");
      if (eq != std::string::npos) s.inputs.emplace_back(rest.substr(0, eq), rest.substr(eq + 3));
    }
  }
  return s;
}

std::string input_differences(const RunStamp& old, const RunStamp& now) {
  const std::map<std::string, std::string> a(old.inputs.begin(), old.inputs.end());
  std::string out;
  for (const auto& [key, sum] : now.inputs) {
    const auto it = a.find(key);
    if (it == a.end() || it->second == sum) continue;  // a new key is a changed key, listed there
    const auto path_of = [](const std::string& v) { return v.substr(0, v.rfind(" crc32 ")); };
    if (path_of(it->second) != path_of(sum)) continue;  // another file: the key itself changed
    out += (out.empty() ? "" : "; ") + key + " " + path_of(sum) +
           " (its content, CRC-32): " + it->second.substr(it->second.rfind(' ') + 1) + " → " +
           sum.substr(sum.rfind(' ') + 1);
  }
  return out;
}

}  // namespace ibrod::driver
