// Time-series analysis of a run (MODEL §6): least-squares lines on automatically chosen final
// windows, the writhe convergence time, transient states. See relaxation.hpp and docs/analysis.md.
#include "diagnostics/relaxation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ibrod::diagnostics {

namespace {

void require_same_size(std::span<const double> t, std::span<const double> y, const char* what) {
  if (t.size() != y.size())
    throw std::invalid_argument(std::string(what) + ": t has " + std::to_string(t.size()) +
                                " samples, the series " + std::to_string(y.size()));
}

/// Fit on [first, first + count) of (x, y); the window's indices are relative to x, y.
LineFit fit_range(std::span<const double> x, std::span<const double> y, std::size_t first,
                  std::size_t count) {
  LineFit f = fit_line(x.subspan(first, count), y.subspan(first, count));
  f.first = first;
  return f;
}

/// The final run [start, n) of samples that satisfy ok(i).
template <class Pred>
std::size_t final_run_start(std::size_t n, Pred ok) {
  std::size_t start = n;
  while (start > 0 && ok(start - 1)) --start;
  return start;
}

}  // namespace

LineFit fit_line(std::span<const double> x, std::span<const double> y) {
  require_same_size(x, y, "fit_line");
  const std::size_t n = x.size();
  if (n < 2) throw std::invalid_argument("fit_line: needs at least 2 points");
  // centred sums: no cancellation when x is far from 0 (late times)
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= double(n), my /= double(n);
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = x[i] - mx, dy = y[i] - my;
    sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
  }
  if (!(sxx > 0)) throw std::invalid_argument("fit_line: all x are equal");
  LineFit f;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  double ss_res = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = y[i] - (f.intercept + f.slope * x[i]);
    ss_res += r * r;
    f.max_abs_residual = std::max(f.max_abs_residual, std::abs(r));
  }
  f.r2 = syy > 0 ? 1.0 - ss_res / syy : 1.0;
  f.first = 0;
  f.count = n;
  return f;
}

std::optional<LineFit> fit_final_linear_window(std::span<const double> x, std::span<const double> y,
                                               const WindowOptions& opt) {
  require_same_size(x, y, "fit_final_linear_window");
  const std::size_t n = x.size();
  const std::size_t lmin = std::max<std::size_t>(opt.min_points, 2);
  if (n < lmin) return std::nullopt;
  auto fit_len = [&](std::size_t len) { return fit_range(x, y, n - len, len); };
  auto passes = [&](const LineFit& f) { return f.max_abs_residual <= opt.tolerance; };

  LineFit best = fit_len(lmin);
  if (!passes(best)) return best;  // no admissible window: the shortest, flagged by its residual
  // grow geometrically until a window fails …
  std::size_t good = lmin, bad = 0;
  while (good < n) {
    const std::size_t len =
        std::min(n, std::max(good + 1, std::size_t(std::ceil(1.05 * double(good)))));
    LineFit f = fit_len(len);
    if (!passes(f)) {
      bad = len;
      break;
    }
    good = len;
    best = f;
  }
  // … then bisect the boundary between the last length that passed and the first that failed
  while (bad > good + 1) {
    const std::size_t mid = good + (bad - good) / 2;
    LineFit f = fit_len(mid);
    if (passes(f)) {
      good = mid;
      best = f;
    } else {
      bad = mid;
    }
  }
  return best;
}

double writhe_convergence_time(std::span<const double> t, std::span<const double> writhe,
                               double delta) {
  require_same_size(t, writhe, "writhe_convergence_time");
  if (t.empty()) throw std::invalid_argument("writhe_convergence_time: empty series");
  const double w_inf = writhe.back();
  std::size_t last_out = t.size();  // last sample outside the band
  for (std::size_t i = t.size(); i-- > 0;) {
    if (std::abs(writhe[i] - w_inf) > delta) {
      last_out = i;
      break;
    }
  }
  if (last_out == t.size()) return t.front();
  // the last sample is inside the band, so i + 1 exists; dev is linear on [t_i, t_{i+1}] and
  // leaves the band through +delta or −delta, whichever side dev_i is on
  const std::size_t i = last_out;
  const double d0 = writhe[i] - w_inf, d1 = writhe[i + 1] - w_inf;
  const double edge = d0 > 0 ? delta : -delta;
  const double s = (d0 - edge) / (d0 - d1);
  return t[i] + s * (t[i + 1] - t[i]);
}

std::optional<ExponentialFit> relaxation_time(std::span<const double> t,
                                              std::span<const double> kinetic,
                                              const WindowOptions& opt) {
  require_same_size(t, kinetic, "relaxation_time");
  const std::size_t n = t.size();
  const std::size_t start = final_run_start(
      n, [&](std::size_t i) { return kinetic[i] > 0 && std::isfinite(kinetic[i]); });
  std::vector<double> lnE(n - start);
  for (std::size_t i = start; i < n; ++i) lnE[i - start] = std::log(kinetic[i]);
  const auto fit = fit_final_linear_window(t.subspan(start), lnE, opt);
  if (!fit || !(fit->slope < 0)) return std::nullopt;
  ExponentialFit e;
  e.line = *fit;
  e.line.first += start;
  e.tau = -2.0 / fit->slope;
  return e;
}

std::optional<ExponentialFit> relaxation_time_from(std::span<const double> t,
                                                   std::span<const double> kinetic, double t_start,
                                                   std::size_t min_points) {
  require_same_size(t, kinetic, "relaxation_time_from");
  std::vector<double> x, y;
  std::size_t first = t.size();
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= t_start && kinetic[i] > 0 && std::isfinite(kinetic[i])) {
      if (x.empty()) first = i;
      x.push_back(t[i]);
      y.push_back(std::log(kinetic[i]));
    }
  if (x.size() < std::max<std::size_t>(min_points, 2)) return std::nullopt;
  const LineFit f = fit_line(x, y);
  if (!(f.slope < 0)) return std::nullopt;
  ExponentialFit e;
  e.line = f;
  e.line.first = first;  // the window's first sample (E_K = 0 samples inside are skipped)
  e.tau = -2.0 / f.slope;
  return e;
}

std::vector<LocalRelaxation> local_relaxation_times(std::span<const double> t,
                                                    std::span<const double> kinetic, double width) {
  require_same_size(t, kinetic, "local_relaxation_times");
  if (!(width > 0)) throw std::invalid_argument("local_relaxation_times: width must be positive");
  std::vector<LocalRelaxation> out;
  if (t.empty()) return out;
  const double t0 = t.front();
  // samples grouped by their window index (computed once per sample, so rounding at a window's
  // edge cannot stall the loop)
  auto window_of = [&](std::size_t j) { return std::floor((t[j] - t0) / width); };
  std::size_t i = 0;
  while (i < t.size()) {
    const double k = window_of(i);
    const double a = t0 + k * width, b = a + width;
    std::vector<double> x, y;
    for (; i < t.size() && window_of(i) == k; ++i)
      if (kinetic[i] > 0 && std::isfinite(kinetic[i])) {
        x.push_back(t[i]);
        y.push_back(std::log(kinetic[i]));
      }
    if (x.size() < 3 || x.back() == x.front()) continue;
    const LineFit f = fit_line(x, y);
    if (f.slope != 0) out.push_back({a, b, -2.0 / f.slope, x.size()});
  }
  return out;
}

double settled_time(std::span<const double> t, std::span<const int> count) {
  if (t.size() != count.size() || t.empty())
    throw std::invalid_argument("settled_time: t and count must be the same size, not empty");
  for (std::size_t i = t.size() - 1; i > 0; --i)
    if (count[i] != count[i - 1]) return t[i];
  return t.front();
}

std::optional<PowerLawFit> power_law_exponent(std::span<const double> t,
                                              std::span<const double> kinetic,
                                              const WindowOptions& opt) {
  require_same_size(t, kinetic, "power_law_exponent");
  const std::size_t n = t.size();
  const std::size_t start = final_run_start(
      n, [&](std::size_t i) { return t[i] > 0 && kinetic[i] > 0 && std::isfinite(kinetic[i]); });
  std::vector<double> lnt(n - start), lnE(n - start);
  for (std::size_t i = start; i < n; ++i) {
    lnt[i - start] = std::log(t[i]);
    lnE[i - start] = std::log(kinetic[i]);
  }
  const auto fit = fit_final_linear_window(lnt, lnE, opt);
  if (!fit) return std::nullopt;
  PowerLawFit p;
  p.line = *fit;
  p.line.first += start;
  p.exponent = fit->slope;
  return p;
}

std::vector<Transient> transients(std::span<const double> t, std::span<const double> kinetic,
                                  std::span<const double> total, const TransientOptions& opt) {
  require_same_size(t, kinetic, "transients");
  require_same_size(t, total, "transients");
  const std::size_t n = t.size();
  std::vector<Transient> out;
  if (n < 3) return out;

  // ln E_K on the samples where it exists (E_K = 0 at rest, e.g. the first row)
  std::vector<std::size_t> v;
  std::vector<double> y;
  for (std::size_t i = 0; i < n; ++i)
    if (kinetic[i] > 0 && std::isfinite(kinetic[i])) {
      v.push_back(i);
      y.push_back(std::log(kinetic[i]));
    }
  // |dE_total/dt|, central differences (one-sided at the ends)
  std::vector<double> rate(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i > 0 ? i - 1 : 0, b = i + 1 < n ? i + 1 : n - 1;
    rate[i] = std::abs((total[b] - total[a]) / (t[b] - t[a]));
  }

  const double min_rise = std::log(opt.min_rise);
  const std::size_t m = v.size();
  for (std::size_t k = 1; k + 1 < m; ++k) {
    if (!(y[k] < y[k - 1] && y[k] <= y[k + 1])) continue;
    // prominence: the highest E_K on each side before the series goes below this minimum
    std::size_t lpeak = k - 1, rpeak = k + 1;
    for (std::size_t l = k; l-- > 0 && y[l] >= y[k];)
      if (y[l] > y[lpeak]) lpeak = l;
    for (std::size_t r = k + 1; r < m && y[r] >= y[k]; ++r)
      if (y[r] > y[rpeak]) rpeak = r;
    if (y[lpeak] - y[k] < min_rise || y[rpeak] - y[k] < min_rise) continue;

    // plateau of E_total: slow dissipation relative to the active phases on either side
    const std::size_t i0 = v[k], a = v[lpeak], b = v[rpeak];
    const double rmax =
        *std::max_element(rate.begin() + std::ptrdiff_t(a), rate.begin() + std::ptrdiff_t(b) + 1);
    const double threshold = opt.plateau_fraction * rmax;
    if (!(rate[i0] <= threshold)) continue;
    std::size_t lo = i0, hi = i0;
    while (lo > a && rate[lo - 1] <= threshold) --lo;
    while (hi < b && rate[hi + 1] <= threshold) ++hi;
    out.push_back({i0, t[i0], kinetic[i0], total[i0], t[lo], t[hi]});
  }
  return out;
}

}  // namespace ibrod::diagnostics
