#include "driver/sweep.hpp"
#include "driver/signals.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "core/error.hpp"
#include "core/text_file.hpp"
#include "config/toml_error.hpp"
#include "io/atomic_file.hpp"

extern char** environ;

namespace ibrod::driver {

using namespace ibrod::config;
using namespace ibrod::io;

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
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
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
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const toml::table* sub = v.as_table()) {
      flatten(*sub, key, out, where);
      continue;
    }
    const toml::array* a = v.as_array();
    if (!a)
      throw ConfigError(where + ": [sweep] " + key + " = " + toml_text(v) +
                        " is invalid: expected a list of values, e.g. [1, 2, 3]");
    if (a->empty())
      throw ConfigError(where + ": [sweep] " + key + " is an empty list: expected at least one value");
    for (const auto& [other, _] : out)
      if (other == key) throw ConfigError(where + ": [sweep] " + key + " is given twice");
    out.emplace_back(key, a);
  }
}

}  // namespace

std::string sanitize_name(const std::string& s) {
  std::string out = s;
  for (char& ch : out) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
                    ch == '.' || ch == '_' || ch == '+' || ch == '=' || ch == ',' || ch == '-';
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
    if (!path) throw ConfigError(where + ": base = " + toml_text(*b) + " is invalid: expected a file name (string)");
    const fs::path p = fs::path(*path).is_absolute() ? fs::path(*path) : dir / *path;
    tree = parse_table(read_text_file(p, where + ": base = \"" + *path + "\""), p.string());
    if (tree.contains("sweep") || tree.contains("base"))
      throw ConfigError(where + ": base = \"" + *path + "\" must be a plain config (no [sweep], no base)");
  }
  for (auto&& [k, v] : doc) {
    const std::string key(k.str());
    if (key == "base") continue;
    if (key == "output_dir") {
      auto o = v.value_exact<std::string>();
      if (!o || o->empty()) throw ConfigError(where + ": output_dir = " + toml_text(v) + " is invalid: expected a directory name (string)");
      sw.output_root = *o;
      continue;
    }
    if (key == "sweep" || key == "names") {
      const toml::table* t = v.as_table();
      if (!t) throw ConfigError(where + ": '" + key + "' must be a table [" + key + "]");
      (key == "sweep" ? sweep_table : names) = t;
      continue;
    }
    if (const toml::table* t = v.as_table()) {
      toml::table overlay;
      overlay.insert(key, *t);
      deep_merge(tree, overlay);
      continue;
    }
    throw ConfigError(where + ": unknown top-level key '" + key +
                      "' (a sweep file has base, output_dir, [names], [sweep] and config sections)");
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
      throw ConfigError(where + ": [sweep] '" + key + "' is not a config key: expected section.key");
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
        if (!s || s->empty()) throw ConfigError(where + ": [names] \"" + key + "\" must be a non-empty string");
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
        throw ConfigError(where + ": [names] \"" + std::string(k.str()) + "\" is not a key of [sweep]");
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

const char* to_string(PointState s) {
  switch (s) {
    case PointState::fresh: return "fresh";
    case PointState::no_checkpoint: return "no_checkpoint";
    case PointState::interrupted: return "interrupted";
    case PointState::finished: return "finished";
    case PointState::failed: return "failed";
  }
  return "?";
}

namespace {

std::string summary_stop_reason(const fs::path& dir) {
  const std::string text = try_read_text_file(dir / "summary.json").value_or("");
  if (text.empty()) return "";
  try {
    const auto j = nlohmann::json::parse(text);
    if (j.contains("stop_reason") && j["stop_reason"].is_string())
      return j["stop_reason"].get<std::string>();
  } catch (const nlohmann::json::exception&) {
  }
  return "";
}

}  // namespace

PointState point_state(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec) || fs::is_empty(dir, ec)) return PointState::fresh;
  const std::string reason = summary_stop_reason(dir);
  if (reason == "end_time" || reason == "equilibrium") return PointState::finished;
  if (reason == "blow_up") return PointState::failed;
  if (fs::exists(dir / "checkpoint.bin", ec)) return PointState::interrupted;
  return PointState::no_checkpoint;
}

// ---- running ----------------------------------------------------------------------------------

namespace {

std::string self_exe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("/proc/self/exe") : p.string();
}

// The children's environment: without the MPI launcher's variables (a child is a plain
// one-process `ibrod run`, not a member of the sweep's MPI job) and, when several run at once on
// one machine and the user set no OMP_NUM_THREADS, with the cores shared out among them.
std::vector<std::string> child_environment(int jobs_here) {
  std::vector<std::string> env;
  bool omp_set = false;
  for (char** e = environ; e && *e; ++e) {
    const std::string v(*e);
    if (v.rfind("OMPI_", 0) == 0 || v.rfind("PMIX_", 0) == 0 || v.rfind("PMI_", 0) == 0) continue;
    if (v.rfind("OMP_NUM_THREADS=", 0) == 0) omp_set = true;
    env.push_back(v);
  }
  if (!omp_set && jobs_here > 1) {
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    env.push_back("OMP_NUM_THREADS=" + std::to_string(std::max(1u, hw / unsigned(jobs_here))));
  }
  return env;
}

pid_t spawn_run(const std::string& binary, const std::vector<std::string>& args,
                const fs::path& log, const std::vector<std::string>& env) {
  std::vector<std::string> a;
  a.push_back(binary);
  a.insert(a.end(), args.begin(), args.end());
  std::vector<char*> argv, envp;
  for (auto& s : a) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_copy = env;
  for (auto& s : env_copy) envp.push_back(s.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, binary.c_str(), &fa, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -rc;
  return pid;
}

std::string last_line(const fs::path& log) {
  const std::string text = try_read_text_file(log).value_or("");
  std::size_t e = text.find_last_not_of("\r\n ");
  if (e == std::string::npos) return "";
  std::size_t b = text.find_last_of("\r\n", e);
  return text.substr(b == std::string::npos ? 0 : b + 1, e - (b == std::string::npos ? 0 : b + 1) + 1);
}

}  // namespace

SweepReport run_sweep(const Sweep& sw, const SweepOptions& opt) {
  SweepReport rep;
  const fs::path root = opt.output_root;
  std::error_code ec;
  fs::create_directories(root / "configs", ec);
  fs::create_directories(root / "logs", ec);
  if (ec) throw RunError("sweep: cannot create '" + (root / "logs").string() + "': " + ec.message());
  if (opt.rank == 0) write_file_atomic(root / "points.csv", points_csv(sw));
  const std::string binary = opt.binary.empty() ? self_exe() : opt.binary;
  const int jobs = std::max(1, opt.jobs);
  const int ranks = std::max(1, opt.ranks);
  auto say = [&](const std::string& s) {
    if (!opt.log) return;
    std::fprintf(opt.log, "%s\n", s.c_str());
    std::fflush(opt.log);
  };
  const std::string tag = ranks > 1 ? "sweep[" + std::to_string(opt.rank) + "]: " : "sweep: ";
  auto fail = [&](const SweepPoint& pt, const std::string& why) {
    ++rep.failed;
    rep.failed_names.push_back(pt.name);
    say(tag + pt.name + ": FAILED: " + why);
  };

  // ---- this rank's points and what each needs
  struct Todo {
    const SweepPoint* pt;
    PointState state;
  };
  std::vector<Todo> todo;
  for (const SweepPoint& pt : sw.points) {
    if (int(pt.index % std::size_t(ranks)) != opt.rank) continue;
    ++rep.points;
    const fs::path dir = root / pt.name;
    const std::string config_text = to_toml(pt.config);
    const PointState st = point_state(dir);
    if (st == PointState::finished || st == PointState::interrupted) {
      // a directory of an earlier, different sweep: never resume or count it as this point
      if (try_read_text_file(dir / "config.toml").value_or("") != config_text) {
        fail(pt, "the run in " + dir.string() + " has another configuration than this sweep "
                 "gives the point; move it away (or delete it) to run the point again");
        continue;
      }
    }
    if (st == PointState::finished) {
      ++rep.skipped;
      continue;
    }
    if (st == PointState::failed) {
      fail(pt, "an earlier run blew up (" + (dir / "summary.json").string() +
                   "); delete the directory to run it again");
      continue;
    }
    write_file_atomic(root / "configs" / (pt.name + ".toml"), config_text);
    todo.push_back({&pt, st});
  }
  say(tag + std::to_string(rep.points) + " points" +
      (ranks > 1 ? " (rank " + std::to_string(opt.rank) + " of " + std::to_string(ranks) + ")" : "") +
      ": " + std::to_string(rep.skipped) + " finished, " + std::to_string(todo.size()) +
      " to run, " + std::to_string(jobs) + " at a time -> " + root.string());

  // ---- K children at a time
  SignalGuard signals(opt.handle_signals, SignalGuard::Mode::sweep);
  const std::vector<std::string> env = child_environment(jobs);
  struct Running {
    const SweepPoint* pt;
    std::chrono::steady_clock::time_point start;
    bool resumed;
  };
  std::map<pid_t, Running> running;
  std::size_t next = 0;
  int forwarded = 0;
  for (;;) {
    const int sig = signals.pending();
    if (sig && sig != forwarded) {  // pass it on; each run checkpoints and stops
      for (const auto& [pid, _] : running) ::kill(pid, sig);
      forwarded = sig;
      rep.signal = sig;
      say(tag + "stopping: " + strsignal(sig) + " passed on to " + std::to_string(running.size()) +
          " runs; run the sweep again to continue");
    }
    while (!sig && int(running.size()) < jobs && next < todo.size()) {
      const Todo& t = todo[next++];
      const fs::path dir = root / t.pt->name;
      const fs::path log = root / "logs" / (t.pt->name + ".log");
      std::vector<std::string> args;
      const bool resume = t.state == PointState::interrupted;
      if (resume) {
        args = {"run", "--resume", dir.string()};
      } else {
        args = {"run", (root / "configs" / (t.pt->name + ".toml")).string(), "-o", dir.string()};
        if (t.state == PointState::no_checkpoint) args.push_back("--overwrite");
      }
      const pid_t pid = spawn_run(binary, args, log, env);
      if (pid <= 0) {
        fail(*t.pt, "cannot start " + binary + ": " + std::strerror(-pid));
        continue;
      }
      (resume ? rep.resumed : rep.fresh)++;
      running[pid] = {t.pt, std::chrono::steady_clock::now(), resume};
      say(tag + "[" + std::to_string(next) + "/" + std::to_string(todo.size()) + "] " +
          t.pt->name + ": " + (resume ? "resuming from its checkpoint" : "started") + " (log " +
          log.string() + ")");
    }
    if (running.empty()) break;
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;  // ECHILD: nothing left (should not happen while running is non-empty)
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;  // not one of ours
    const Running r = it->second;
    running.erase(it);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
    const fs::path dir = root / r.pt->name;
    const fs::path log = root / "logs" / (r.pt->name + ".log");
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    const int killed_by = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    if (code == 0 && point_state(dir) == PointState::finished) {
      ++rep.completed;
      char buf[64];
      std::snprintf(buf, sizeof buf, " (%.1f s)", secs);
      say(tag + r.pt->name + ": finished" + buf);
    } else if (rep.signal && (code == 128 + SIGINT || code == 128 + SIGTERM ||
                              killed_by == SIGINT || killed_by == SIGTERM)) {
      say(tag + r.pt->name + ": stopped, checkpoint kept");
    } else {
      const std::string why = killed_by ? std::string("killed by signal ") + strsignal(killed_by)
                                        : "exit status " + std::to_string(code);
      fail(*r.pt, why + ": " + last_line(log) + " (log " + log.string() + ")");
    }
  }
  say(tag + "done: " + std::to_string(rep.completed) + " finished now, " +
      std::to_string(rep.skipped) + " already finished, " + std::to_string(rep.failed) +
      " failed" + (rep.signal ? ", stopped by a signal" : ""));
  return rep;
}

}  // namespace ibrod::driver
