#include "driver/sweep_runner.hpp"

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
#include <map>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/text_file.hpp"
#include "driver/dir_lock.hpp"
#include "driver/signals.hpp"
#include "io/atomic_file.hpp"
#include "io/run_dir.hpp"

namespace ibrod::driver {

using namespace ibrod::io;

namespace fs = std::filesystem;

const char* to_string(PointState s) {
  switch (s) {
    case PointState::fresh:
      return "fresh";
    case PointState::no_checkpoint:
      return "no_checkpoint";
    case PointState::interrupted:
      return "interrupted";
    case PointState::finished:
      return "finished";
    case PointState::failed:
      return "failed";
    case PointState::running:
      return "running";
  }
  return "?";
}

namespace {

std::string summary_stop_reason(const fs::path& dir) {
  const std::string text = try_read_text_file(RunDir(dir).summary()).value_or("");
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
  if (dir_lock_holder(dir)) return PointState::running;
  const std::string reason = summary_stop_reason(dir);
  if (reason == "end_time" || reason == "equilibrium") return PointState::finished;
  if (reason == "blow_up") return PointState::failed;
  if (fs::exists(RunDir(dir).checkpoint(), ec)) return PointState::interrupted;
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
  return text.substr(b == std::string::npos ? 0 : b + 1,
                     e - (b == std::string::npos ? 0 : b + 1) + 1);
}

}  // namespace

SweepReport run_sweep(const Sweep& sw, const SweepOptions& opt) {
  SweepReport rep;
  const fs::path root = opt.output_root;
  const SweepDir sweep_dir{root};
  std::error_code ec;
  fs::create_directories(sweep_dir.configs(), ec);
  fs::create_directories(sweep_dir.logs(), ec);
  if (ec)
    throw RunError("sweep: cannot create '" + sweep_dir.logs().string() + "': " + ec.message());
  if (opt.only_point < 0) {
    if (opt.rank == 0) write_file_atomic(sweep_dir.points(), points_csv(sw));
  } else if (!fs::exists(sweep_dir.points(), ec)) {
    // the tasks of a job array start together: whichever writes it, it is the same file
    try {
      write_file_atomic(sweep_dir.points(), points_csv(sw));
    } catch (const RunError&) {
    }
  }
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
    if (opt.only_point >= 0 ? pt.index != std::size_t(opt.only_point)
                            : int(pt.index % std::size_t(ranks)) != opt.rank)
      continue;
    ++rep.points;
    const fs::path dir = sweep_dir.run(pt.name);
    const std::string config_text = to_toml(pt.config);
    const PointState st = point_state(dir);
    if (st == PointState::running) {
      // another process writes it (e.g. the orphaned run of a sweep that was killed): one writer
      ++rep.running;
      const auto holder = dir_lock_holder(dir);
      say(tag + pt.name + ": running in another process" +
          (holder && *holder > 0 ? " (PID " + std::to_string(*holder) + ")" : std::string()) +
          "; not started again");
      continue;
    }
    if (st == PointState::finished || st == PointState::interrupted) {
      // a directory of an earlier, different sweep: never resume or count it as this point
      // compared key by key (not as text): a directory written by an older ibrod, whose
      // config.toml is laid out differently, is still the same point
      const auto old_text = try_read_text_file(RunDir(dir).config());
      if (!old_text ||
          !config::config_differences(*old_text, pt.config, RunDir(dir).config().string())
               .empty()) {
        fail(pt, "the run in " + dir.string() +
                     " has another configuration than this sweep "
                     "gives the point; move it away (or delete it) to run the point again");
        continue;
      }
    }
    if (st == PointState::finished) {
      ++rep.skipped;
      continue;
    }
    if (st == PointState::failed) {
      fail(pt, "an earlier run blew up (" + (RunDir(dir).summary()).string() +
                   "); delete the directory to run it again");
      continue;
    }
    write_file_atomic(sweep_dir.config(pt.name), config_text);
    todo.push_back({&pt, st});
  }
  say(tag + std::to_string(rep.points) + " points" +
      (ranks > 1 ? " (rank " + std::to_string(opt.rank) + " of " + std::to_string(ranks) + ")"
                 : "") +
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
      const fs::path dir = sweep_dir.run(t.pt->name);
      const fs::path log = sweep_dir.log(t.pt->name);
      std::vector<std::string> args;
      const bool resume = t.state == PointState::interrupted;
      if (resume) {
        args = {"run", "--resume", dir.string()};
      } else {
        args = {"run", sweep_dir.config(t.pt->name).string(), "-o", dir.string()};
        if (t.state == PointState::no_checkpoint) args.push_back("--overwrite");
      }
      const pid_t pid = spawn_run(binary, args, log, env);
      if (pid <= 0) {
        fail(*t.pt, "cannot start " + binary + ": " + std::strerror(-pid));
        continue;
      }
      (resume ? rep.resumed : rep.fresh)++;
      running[pid] = {t.pt, std::chrono::steady_clock::now(), resume};
      say(tag + "[" + std::to_string(next) + "/" + std::to_string(todo.size()) + "] " + t.pt->name +
          ": " + (resume ? "resuming from its checkpoint" : "started") + " (log " + log.string() +
          ")");
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
    const fs::path dir = sweep_dir.run(r.pt->name);
    const fs::path log = sweep_dir.log(r.pt->name);
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
    } else if (const PointState now = code == 2 ? point_state(dir) : PointState::fresh;
               code == 2 && (now == PointState::running ||
                             last_line(log).find("is being written by another ibrod process") !=
                                 std::string::npos)) {
      // another process (a second sweep on the same directory) started the point between the
      // look at it and this start: the lock refused this run; the point is healthy
      ++rep.running;
      const auto holder = dir_lock_holder(dir);
      say(tag + r.pt->name + ": running in another process" +
          (holder && *holder > 0 ? " (PID " + std::to_string(*holder) + ")" : std::string()) +
          "; not started again");
    } else if (code == 2 && now == PointState::finished) {
      // ... or ran it to its end in that time
      ++rep.skipped;
      say(tag + r.pt->name + ": finished by another process meanwhile");
    } else {
      const std::string why = killed_by ? std::string("killed by signal ") + strsignal(killed_by)
                                        : "exit status " + std::to_string(code);
      fail(*r.pt, why + ": " + last_line(log) + " (log " + log.string() + ")");
    }
  }
  say(tag + "done: " + std::to_string(rep.completed) + " finished now, " +
      std::to_string(rep.skipped) + " already finished, " + std::to_string(rep.failed) + " failed" +
      (rep.running ? ", " + std::to_string(rep.running) + " still running elsewhere" : "") +
      (rep.signal ? ", stopped by a signal" : ""));
  return rep;
}

}  // namespace ibrod::driver