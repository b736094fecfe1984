// `ibrod compare` (cmd_compare.hpp); the work is in analysis/compare.hpp.
#include "cmd_compare.hpp"

#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "analysis/compare.hpp"
#include "exit_status.hpp"
#include "io/atomic_file.hpp"

namespace {

struct CompareArgs {
  std::string a, b, json;
  ibrod::analysis::CompareOptions opt;
  ibrod::analysis::CompareLimits limits;
  double contact_distance_A = 0;
  bool quiet = false;
};

/// The comparison, printed; returns the exit status (cmd_compare.hpp).
int run_compare(const CompareArgs& x) {
  using namespace ibrod::analysis;
  const Comparison c = compare_run_dirs(x.a, x.b, x.opt, x.contact_distance_A);
  const std::vector<std::string> failures = compare_failures(c, x.limits);
  if (!c.shapes_note.empty())
    std::fprintf(stderr, "ibrod compare: note: shapes %s: %s\n",
                 c.shapes_compared ? "compared where both have frames" : "not compared",
                 c.shapes_note.c_str());
  if (!x.quiet) {
    std::printf("compare: A = %s, B = %s (d = B - A; d_c = %.4g / %.4g A; guard %.4g us)\n",
                x.a.c_str(), x.b.c_str(), c.contact_distance_a_A, c.contact_distance_b_A,
                x.opt.guard_us);
    std::printf("%s", compare_table(c).c_str());
  }
  std::printf("%s\n", compare_summary(c).c_str());
  if (!x.json.empty()) ibrod::io::write_file_atomic(x.json, compare_json(c, x.limits, failures));
  if (!x.limits.any()) return 0;
  for (const auto& f : failures) std::printf("compare: FAIL: %s\n", f.c_str());
  if (failures.empty()) std::printf("compare: PASS\n");
  return failures.empty() ? 0 : 1;
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto x = std::make_shared<CompareArgs>();
  auto* cmp = app.add_subcommand(
      "compare",
      "compare run B with run A at their common times: max |dWr|, |dE_total| and |d closest "
      "approach|, the last common row's dWr and dE_total, and the shape class and loops of "
      "every common frame; with a --max-* limit, exit status 1 when it is exceeded or a shape "
      "differs outside the guard; see docs/analysis.md");
  cmp->add_option("run_a", x->a, "run directory A (e.g. the explicit reference)")->required();
  cmp->add_option("run_b", x->b, "run directory B (e.g. the implicit run)")->required();
  cmp->add_option("--max-dwr", x->limits.max_dwr,
                  "largest allowed max |Wr_B - Wr_A| over the common times")
      ->check(CLI::NonNegativeNumber);
  cmp->add_option("--max-de", x->limits.max_de_kT,
                  "largest allowed max |E_total,B - E_total,A| over the common times, kT")
      ->check(CLI::NonNegativeNumber);
  cmp->add_option("--max-final-de", x->limits.max_final_de_kT,
                  "largest allowed |E_total,B - E_total,A| at the last common time, kT")
      ->check(CLI::NonNegativeNumber);
  cmp->add_option("--guard-us", x->opt.guard_us,
                  "a shape difference within this many us of a change of class or loops in "
                  "either run is not a mismatch")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmp->add_option("--contact-distance", x->contact_distance_A,
                  "contact distance d_c of the shapes in A (default: D + 3 Debye lengths of "
                  "each run's config.toml)")
      ->check(CLI::PositiveNumber);
  cmp->add_option("--json", x->json, "also write the numbers and the per-frame table as JSON");
  cmp->add_flag("-q,--quiet", x->quiet, "print the summary line (and verdict) only, no table");
  cmp->callback([x] {
    int status = 0;
    try {
      status = run_compare(*x);
    } catch (const std::exception& e) {
      status = ibrod::app::report_error(e);
    }
    std::fflush(stdout);
    throw CLI::RuntimeError(status);
  });
}
