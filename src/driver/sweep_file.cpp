#include "driver/sweep_file.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <map>
#include <sstream>

#include <toml++/toml.h>

#include "config/toml_error.hpp"
#include "core/error.hpp"
#include "core/text_file.hpp"

namespace ibrod::driver {

using namespace ibrod::config;

namespace fs = std::filesystem;

namespace {

// ---- TOML trees -------------------------------------------------------------------------------

std::vector<std::string> split_key(const std::string& key) {
  std::vector<std::string> parts;
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = key.find('.', b);
    parts.push_back(key.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  return parts;
}

void copy_into(toml::table& dst, std::string_view key, const toml::node& v) {
  v.visit([&](auto&& x) { dst.insert_or_assign(key, x); });
}

// dst ← dst with src's entries on top (tables merged key by key, everything else replaced)
void deep_merge(toml::table& dst, const toml::table& src) {
  for (auto&& [k, v] : src) {
    toml::table* d = dst[k.str()].as_table();
    if (const toml::table* s = v.as_table(); s && d)
      deep_merge(*d, *s);
    else
      copy_into(dst, k.str(), v);
  }
}

// Sets tree[a][b][c] = v for key "a.b.c", creating tables on the way.
void set_path(toml::table& tree, const std::string& key, const toml::node& v,
              const std::string& where) {
  const auto parts = split_key(key);
  toml::table* t = &tree;
  std::size_t first = 0;
  // rods.K.key: key of [[rods]] table K (K = the number of tables appends one), as --set
  if (parts.size() == 3 && parts[0] == "rods") {
    std::size_t r = 0;
    const auto [end, ec] = std::from_chars(parts[1].data(), parts[1].data() + parts[1].size(), r);
    if (!tree.contains("rods")) tree.insert("rods", toml::array{});
    toml::array* a = tree["rods"].as_array();
    if (ec != std::errc() || end != parts[1].data() + parts[1].size() || !a ||
        (!a->empty() && !a->is_array_of_tables()) || r > a->size())
      throw ConfigError(
          where + ": '" + key + "': a [[rods]] key is rods.K.key with K a table number from 0 to " +
          std::to_string(a && a->is_array_of_tables() ? a->size() : 0) + " (" +
          std::to_string(a && a->is_array_of_tables() ? a->size() : 0) + " appends a table)");
    if (r == a->size()) a->push_back(toml::table{});
    t = a->get(r)->as_table();
    first = 2;
  }
  for (std::size_t i = first; i + 1 < parts.size(); ++i) {
    if (!t->contains(parts[i])) t->insert(parts[i], toml::table{});
    toml::table* next = (*t)[parts[i]].as_table();
    if (!next)
      throw ConfigError(where + ": '" + key + "': '" + parts[i] +
                        "' is a value, not a section or a table-valued key");
    t = next;
  }
  copy_into(*t, parts.back(), v);
}

std::string shortest(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// A value in point names (sanitize_name is applied to the whole name afterwards).
std::string label_of(const toml::node& n) {
  if (auto v = n.value_exact<int64_t>()) return std::to_string(*v);
  if (auto v = n.value_exact<double>()) return shortest(*v);
  if (auto v = n.value_exact<bool>()) return *v ? "true" : "false";
  if (auto v = n.value_exact<std::string>()) return *v;
  std::string s;
  if (const toml::array* a = n.as_array())
    for (const toml::node& e : *a) {
      if (!s.empty()) s += ',';
      s += label_of(e);
    }
  if (const toml::table* t = n.as_table())
    for (auto&& [k, e] : *t) {
      if (!s.empty()) s += ',';
      s += std::string(k.str());
      s += '=';
      s += label_of(e);
    }
  return s;
}

std::string toml_text(const toml::node& n) {
  if (auto v = n.value_exact<double>()) {
    std::string s = shortest(*v);
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // stays a float in TOML
    return s;
  }
  std::ostringstream os;
  n.visit([&](auto&& x) { os << x; });
  return os.str();
}

Config config_of(const toml::table& tree, const std::string& source) {
  std::ostringstream os;
  os << tree;
  Config c;
  apply_toml(c, os.str(), source);
  return c;
}

toml::table parse_table(const std::string& text, const std::string& source) {
  return config::parse_toml(text, source, "sweep");
}

// Short names in point names: a few well-known keys, otherwise the last part of the key.
std::string default_short_name(const std::string& key) {
  if (key == "rod.excess_link") return "dlk";
  return split_key(key).back();
}

// Flattens [sweep] (quoted "a.b" keys and dotted a.b keys alike) into key → list.
void flatten(const toml::table& t, const std::string& prefix,
             std::vector<std::pair<std::string, const toml::array*>>& out,
             const std::string& where) {
  for (auto&& [k, v] : t) {
    const std::string key =
        prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const toml::table* sub = v.as_table()) {
      flatten(*sub, key, out, where);
      continue;
    }
    const toml::array* a = v.as_array();
    if (!a)
      throw ConfigError(where + ": [sweep] " + key + " = " + toml_text(v) +
                        " is invalid: expected a list of values, e.g. [1, 2, 3]");
    if (a->empty())
      throw ConfigError(where + ": [sweep] " + key +
                        " is an empty list: expected at least one value");
    for (const auto& [other, _] : out)
      if (other == key) throw ConfigError(where + ": [sweep] " + key + " is given twice");
    out.emplace_back(key, a);
  }
}

}  // namespace

std::string sanitize_name(const std::string& s) {
  std::string out = s;
  for (char& ch : out) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '.' || ch == '_' || ch == '+' || ch == '=' ||
                    ch == ',' || ch == '-';
    if (!ok) ch = '-';
  }
  if (out.empty() || out[0] == '.') out = "_" + out;  // no hidden or empty names
  // keep names within NAME_MAX: long ones end in a hash of the whole name (still stable)
  if (out.size() > 200) {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a
    for (unsigned char ch : s) h = (h ^ ch) * 1099511628211ull;
    char buf[20];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    out = out.substr(0, 180) + "_" + buf;
  }
  return out;
}

Sweep parse_sweep(const std::string& text, const std::string& source, const fs::path& dir) {
  const std::string where = "sweep: " + source;
  const toml::table doc = parse_table(text, source);
  Sweep sw;
  sw.source = source;

  // ---- the base tree: `base = …`, then the file's own sections on top
  toml::table tree;
  const toml::table* sweep_table = nullptr;
  const toml::table* names = nullptr;
  if (const toml::node* b = doc.get("base")) {
    auto path = b->value_exact<std::string>();
    if (!path)
      throw ConfigError(where + ": base = " + toml_text(*b) +
                        " is invalid: expected a file name (string)");
    const fs::path p = fs::path(*path).is_absolute() ? fs::path(*path) : dir / *path;
    tree = parse_table(read_text_file(p, where + ": base = \"" + *path + "\""), p.string());
    if (tree.contains("sweep") || tree.contains("base"))
      throw ConfigError(where + ": base = \"" + *path +
                        "\" must be a plain config (no [sweep], no base)");
  }
  for (auto&& [k, v] : doc) {
    const std::string key(k.str());
    if (key == "base") continue;
    if (key == "output_dir") {
      auto o = v.value_exact<std::string>();
      if (!o || o->empty())
        throw ConfigError(where + ": output_dir = " + toml_text(v) +
                          " is invalid: expected a directory name (string)");
      sw.output_root = *o;
      continue;
    }
    if (key == "sweep" || key == "names") {
      const toml::table* t = v.as_table();
      if (!t) throw ConfigError(where + ": '" + key + "' must be a table [" + key + "]");
      (key == "sweep" ? sweep_table : names) = t;
      continue;
    }
    if (key == "rods" && v.is_array()) {  // [[rods]] tables: replace the base's (as in a config)
      copy_into(tree, key, v);
      continue;
    }
    if (const toml::table* t = v.as_table()) {
      toml::table overlay;
      overlay.insert(key, *t);
      deep_merge(tree, overlay);
      continue;
    }
    throw ConfigError(
        where + ": unknown top-level key '" + key +
        "' (a sweep file has base, output_dir, [names], [sweep], config sections and [[rods]] "
        "tables)");
  }
  if (!sweep_table || sweep_table->empty())
    throw ConfigError(where + ": no [sweep] table: expected [sweep] with key = [values…]");
  try {
    (void)config_of(tree, source);
  } catch (const ConfigError& e) {
    throw ConfigError(where + ": the base configuration is invalid: " + e.what());
  }

  // ---- axes: each key and each value checked against the config schema on its own
  std::vector<std::pair<std::string, const toml::array*>> lists;
  flatten(*sweep_table, "", lists, where);
  // in the order of the file (toml++ tables iterate in key order)
  std::stable_sort(lists.begin(), lists.end(), [](const auto& a, const auto& b) {
    const auto& pa = a.second->source().begin;
    const auto& pb = b.second->source().begin;
    return pa.line != pb.line ? pa.line < pb.line : pa.column < pb.column;
  });
  std::map<std::string, int> leaf_count;
  for (const auto& [key, _] : lists) ++leaf_count[default_short_name(key)];
  for (const auto& [key, arr] : lists) {
    if (key.find('.') == std::string::npos)
      throw ConfigError(where + ": [sweep] '" + key +
                        "' is not a config key: expected section.key");
    SweepAxis ax;
    ax.key = key;
    ax.short_name = default_short_name(key);
    if (leaf_count[ax.short_name] > 1) {  // rod.x and grid.x: spell the section out
      ax.short_name = key;
      for (char& ch : ax.short_name)
        if (ch == '.') ch = '-';
    }
    if (names)
      if (const toml::node* nm = names->get(key)) {
        auto s = nm->value_exact<std::string>();
        if (!s || s->empty())
          throw ConfigError(where + ": [names] \"" + key + "\" must be a non-empty string");
        ax.short_name = *s;
      }
    for (const toml::node& v : *arr) {
      toml::table t = tree;
      set_path(t, key, v, where + ": [sweep]");
      try {
        (void)config_of(t, source);
      } catch (const ConfigError& e) {
        throw ConfigError(where + ": [sweep] " + key + " = " + toml_text(v) + ": " + e.what());
      }
      ax.values.push_back(toml_text(v));
      ax.labels.push_back(label_of(v));
    }
    sw.axes.push_back(std::move(ax));
  }
  if (names)
    for (auto&& [k, _] : *names) {
      bool found = false;
      for (const auto& ax : sw.axes) found = found || ax.key == k.str();
      if (!found)
        throw ConfigError(where + ": [names] \"" + std::string(k.str()) +
                          "\" is not a key of [sweep]");
    }

  // ---- the product, first axis slowest
  std::size_t total = 1;
  for (const auto& [_, arr] : lists) {
    total *= arr->size();
    if (total > 1000000) throw ConfigError(where + ": [sweep] has more than 10⁶ points");
  }
  std::map<std::string, std::size_t> seen;
  for (std::size_t idx = 0; idx < total; ++idx) {
    SweepPoint pt;
    pt.index = idx;
    toml::table t = tree;
    std::string name;
    std::size_t rest = idx, stride = total;
    for (std::size_t a = 0; a < lists.size(); ++a) {
      stride /= lists[a].second->size();
      const std::size_t j = rest / stride;
      rest %= stride;
      const toml::node& v = *lists[a].second->get(j);
      set_path(t, lists[a].first, v, where + ": [sweep]");
      pt.assignments.emplace_back(lists[a].first, sw.axes[a].values[j]);
      if (a) name += '_';
      name += sw.axes[a].short_name;
      name += '=';
      name += sw.axes[a].labels[j];
    }
    pt.name = sanitize_name(name);
    try {
      pt.config = config_of(t, source);
      validate(pt.config);
    } catch (const ConfigError& e) {
      throw ConfigError(where + ": point " + pt.name + ": " + e.what());
    }
    if (auto [it, fresh] = seen.emplace(pt.name, idx); !fresh)
      throw ConfigError(where + ": points " + std::to_string(it->second) + " and " +
                        std::to_string(idx) + " have the same name '" + pt.name +
                        "' (a value repeated in a [sweep] list, or [names] that collide)");
    sw.points.push_back(std::move(pt));
  }
  return sw;
}

Sweep load_sweep(const fs::path& file) {
  return parse_sweep(read_text_file(file, "sweep"), file.string(), file.parent_path());
}

std::string points_csv(const Sweep& sw) {
  std::string s = "index,name";
  for (const auto& ax : sw.axes) s += "," + ax.key;
  s += "\n";
  for (const auto& pt : sw.points) {
    s += std::to_string(pt.index) + "," + pt.name;
    for (const auto& [_, v] : pt.assignments) {
      // values with commas or quotes (arrays, tables, strings) are quoted CSV fields
      if (v.find_first_of(",\"") == std::string::npos) {
        s += "," + v;
      } else {
        std::string q;
        for (char ch : v) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
        s += ",\"" + q + "\"";
      }
    }
    s += "\n";
  }
  return s;
}

// ---- point states ---------------------------------------------------------------------------
}  // namespace ibrod::driver
