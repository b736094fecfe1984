// `ibrod analyze` and `ibrod render` (cmd_analysis.hpp); the work is in analysis/analyze.hpp and
// analysis/frames.hpp.
#include "cmd_analysis.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "analysis/frames.hpp"
#include "core/error.hpp"
#include "exit_status.hpp"
#include "render/render.hpp"

namespace {

/// Runs a subcommand's work and ends parsing with its exit status (cmd_analysis.hpp).
[[noreturn]] void finish(const std::function<void()>& work) {
  int status = 0;
  try {
    work();
  } catch (const std::exception& e) {
    status = ibrod::app::report_error(e);
  }
  std::fflush(stdout);
  throw CLI::RuntimeError(status);
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

/// python/ibrod_report.py (with ibrod_plot.py and ibrod_study.py beside it), the first found of:
///   $IBROD_REPORT_SCRIPT;
///   installed beside the binary: <bindir>/<IBROD_SCRIPTS_FROM_BINDIR>/ (cmake --install: bin/ →
///   share/ibrod/; pip install: ibrod/bin/ → ibrod/share/ibrod/);
///   the source tree this binary was built from (IBROD_SOURCE_PYTHON_DIR: any build directory);
///   ../../python/ from the binary (an in-tree build/app/ibrod moved with its source tree).
std::filesystem::path report_script() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("IBROD_REPORT_SCRIPT")) return env;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  std::vector<fs::path> where;
  if (!ec) where.push_back(exe.parent_path() / IBROD_SCRIPTS_FROM_BINDIR / "ibrod_report.py");
  where.push_back(fs::path(IBROD_SOURCE_PYTHON_DIR) / "ibrod_report.py");
  if (!ec) where.push_back(exe.parent_path() / "../../python/ibrod_report.py");
  std::string looked;
  for (const fs::path& p : where) {
    if (fs::is_regular_file(p, ec)) return fs::weakly_canonical(p);
    looked += (looked.empty() ? "" : ", ") + p.lexically_normal().string();
  }
  throw ibrod::ConfigError("ibrod report: python/ibrod_report.py not found (looked in " + looked +
                           "; set IBROD_REPORT_SCRIPT to its path)");
}

/// The Python that runs the report: $IBROD_PYTHON (the pip-installed `ibrod` command sets it to
/// its environment's interpreter), else Debian's /usr/bin/python3 (numpy, matplotlib).
std::string report_python() {
  const char* env = std::getenv("IBROD_PYTHON");
  return env && *env ? env : "/usr/bin/python3";
}

}  // namespace

void add_analysis_commands(CLI::App& app) {
  // ---- report: the Python report, called the same way (docs/analysis.md)
  auto* report = app.add_subcommand(
      "report",
      "write the report of a sweep (tables, figures, contact sheet) with "
      "python/ibrod_report.py: ibrod report RUN_DIR... -o REPORT_DIR [--frames]; the "
      "binary is passed as --ibrod, so runs are analysed first");
  report->prefix_command();  // every argument goes to the script
  report->callback([report] {
    finish([&] {
      const std::string script = report_script().string();
      std::error_code ec;
      const std::string self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
      const std::string python = report_python();
      std::vector<std::string> args{python, script};
      for (const auto& r : report->remaining()) args.push_back(r);
      if (!ec) args.insert(args.end(), {"--ibrod", self});
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      std::fflush(stdout);
      ::execv(argv[0], argv.data());
      throw ibrod::RunError("ibrod report: cannot run " + python + ": " + std::strerror(errno));
    });
  });

  // ---- analyze
  struct AnalyzeArgs {
    std::string dir;
    ibrod::analysis::AnalyzeOptions opt;
    bool quiet = false;
  };
  auto a = std::make_shared<AnalyzeArgs>();
  auto* analyze = app.add_subcommand(
      "analyze",
      "add the time-series analysis (writhe convergence, relaxation time τ, transient "
      "states, power law) and the shape of the final state (with --frames of every "
      "frame) to DIR/summary.json; see docs/analysis.md");
  analyze->add_option("dir", a->dir, "run directory (written by ibrod run)")->required();
  analyze
      ->add_option("--delta", a->opt.writhe_delta,
                   "band |Wr − Wr(∞)| of the writhe convergence time")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  analyze
      ->add_option("--fit-tolerance", a->opt.fit.tolerance,
                   "largest |residual| of ln E_K in a fit window (0.02: 2 %)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  analyze->add_flag(
      "--frames", a->opt.every_frame,
      "also the shape of every frame of DIR/trajectory.h5md (summary.json shape_frames)");
  analyze
      ->add_option("--contact-distance", a->opt.contact_distance_A,
                   "contact distance d_c in Å (default: D + 3 Debye lengths of config.toml)")
      ->check(CLI::PositiveNumber);
  analyze->add_option("--tau-window", a->opt.tau_window_us, "window of τ(t) in µs")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  analyze->add_flag("-q,--quiet", a->quiet,
                    "print nothing on success (warnings still go to stderr)");
  analyze->callback([a] {
    finish([&] {
      const auto result = ibrod::analysis::analyze_run(a->dir, a->opt);
      for (const auto& w : result.warnings)
        std::fprintf(stderr, "ibrod analyze: warning: %s: %s\n", a->dir.c_str(), w.c_str());
      if (!a->quiet) std::printf("%s\n", ibrod::analysis::analysis_json(result, a->opt).c_str());
    });
  });

  // ---- render
  struct RenderArgs {
    std::string dir, size = "800x800";
    ibrod::analysis::RenderOptions opt;
  };
  auto r = std::make_shared<RenderArgs>();
  auto* render = app.add_subcommand(
      "render", "draw the rod as a shaded tube with a stripe along D1 into DIR/render/*.png");
  render->add_option("dir", r->dir, "run directory (written by ibrod run)")->required();
  render
      ->add_option("--time", r->opt.times,
                   "time in µs (nearest frame of DIR/trajectory.h5md) or 'final'; repeatable or "
                   "comma-separated (default: final)")
      ->delimiter(',');
  render
      ->add_option("--views", r->opt.views,
                   "comma-separated, of: " + join(ibrod::render::standard_view_names()))
      ->delimiter(',')
      ->default_str(join(r->opt.views));
  render->add_option("--size", r->size, "image size WxH in pixels")->capture_default_str();
  render->add_flag("--force", r->opt.force,
                   "replace pictures that exist (without it an existing file is an error)");
  render
      ->add_option("--colour", r->opt.colour,
                   "body colour: stripe (blue, with an orange stripe along D1), along (a colour "
                   "map from the first point to the last), height (a colour map of z) or twist "
                   "(a colour map of the twist density, lowest to highest)")
      ->check(CLI::IsMember({"stripe", "along", "height", "twist"}))
      ->capture_default_str();
  render->add_flag("!--no-labels", r->opt.labels,
                   "no time, Wr, ΔLk, Cs and scale bar on the pictures");
  render->add_flag("--movie", r->opt.movie,
                   "every frame of DIR/trajectory.h5md from the first view, at one scale, into "
                   "DIR/render/movie_<view>/frame_NNNNN.png, as the animated PNG "
                   "DIR/render/rod_<view>.apng, and DIR/render/rod_<view>.mp4 with ffmpeg if "
                   "installed");
  render->callback([r] {
    finish([&] {
      ibrod::analysis::parse_size(r->size, r->opt.width, r->opt.height);
      ibrod::analysis::render_run(r->dir, r->opt, stdout);
    });
  });
}
