#pragma once
// Reading a whole file into memory, the one way every layer does it: a path that is missing, a
// directory, a FIFO or device, or unreadable is a ConfigError that says which (a FIFO is refused
// before it is opened, so that reading never blocks).
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace ibrod {

/// Why `path` cannot be read as a regular file ("" if it can be opened for reading).
inline std::string unreadable_reason(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return "the path is empty";
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) return "it does not exist";
  if (fs::is_directory(st)) return "it is a directory";
  if (!fs::is_regular_file(st)) return "it is not a regular file";
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::strerror(errno);
  return "";
}

/// The whole file, or nothing if it cannot be read (see unreadable_reason for why).
inline std::optional<std::string> try_read_text_file(const std::filesystem::path& path) {
  if (!unreadable_reason(path).empty()) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The whole file. Throws ConfigError "<what>: cannot read file '<path>': <reason>".
inline std::string read_text_file(const std::filesystem::path& path, const std::string& what) {
  if (auto text = try_read_text_file(path)) return *std::move(text);
  std::string reason = unreadable_reason(path);
  if (reason.empty()) reason = "read error";
  throw ConfigError(what + ": cannot read file '" + path.string() + "': " + reason);
}

}  // namespace ibrod
