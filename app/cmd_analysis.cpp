// `ibrod analyze` and `ibrod render` (cmd_analysis.hpp); the work is in analysis/analyze.hpp and
// analysis/frames.hpp.
#include "cmd_analysis.hpp"

#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "exit_status.hpp"
#include "analysis/frames.hpp"
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

}  // namespace

void add_analysis_commands(CLI::App& app) {
  // ---- analyze
  struct AnalyzeArgs {
    std::string dir;
    ibrod::analysis::AnalyzeOptions opt;
    bool quiet = false;
  };
  auto a = std::make_shared<AnalyzeArgs>();
  auto* analyze = app.add_subcommand(
      "analyze", "add the time-series analysis (writhe convergence, relaxation time τ, transient "
                 "states, power law) to DIR/summary.json; see docs/analysis.md");
  analyze->add_option("dir", a->dir, "run directory (written by ibrod run)")->required();
  analyze->add_option("--delta", a->opt.writhe_delta,
                      "band |Wr − Wr(∞)| of the writhe convergence time")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  analyze->add_option("--fit-tolerance", a->opt.fit.tolerance,
                      "largest |residual| of ln E_K in a fit window (0.02: 2 %)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  analyze->add_flag("-q,--quiet", a->quiet, "print nothing on success");
  analyze->callback([a] {
    finish([&] {
      const auto result = ibrod::analysis::analyze_run(a->dir, a->opt);
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
  render->add_option("--time", r->opt.times,
                     "time in µs (nearest frame of DIR/trajectory.h5) or 'final'; repeatable or "
                     "comma-separated (default: final)")
      ->delimiter(',');
  render->add_option("--views", r->opt.views,
                     "comma-separated, of: " + join(ibrod::render::standard_view_names()))
      ->delimiter(',')
      ->default_str(join(r->opt.views));
  render->add_option("--size", r->size, "image size WxH in pixels")->capture_default_str();
  render->callback([r] {
    finish([&] {
      ibrod::analysis::parse_size(r->size, r->opt.width, r->opt.height);
      ibrod::analysis::render_run(r->dir, r->opt, stdout);
    });
  });
}
