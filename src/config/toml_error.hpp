#pragma once
// One format for TOML syntax errors, wherever a TOML document is parsed (configs, sweep files,
// a run directory's config.toml): "<what>: <source>:<line>:<column>: TOML syntax error: <why>".
#include <sstream>
#include <string>

#include <toml++/toml.h>

#include "config/detail.hpp"
#include "core/error.hpp"

namespace ibrod::config {

inline ConfigError toml_syntax_error(const std::string& what, const std::string& source,
                                     const toml::parse_error& e) {
  std::ostringstream os;
  os << what << ": " << source << ":" << e.source().begin.line << ":" << e.source().begin.column
     << ": TOML syntax error: " << detail::echo(std::string(e.description()), 200);
  return ConfigError(os.str());
}

/// toml::parse with toml_syntax_error on failure.
inline toml::table parse_toml(const std::string& text, const std::string& source,
                              const std::string& what) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw toml_syntax_error(what, source, e);
  }
}

}  // namespace ibrod::config
