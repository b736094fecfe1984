#pragma once
// Time-series analysis of a run (MODEL §6, last item): writhe convergence time, the relaxation
// time τ of E_K ∝ exp(−2t/τ) on the final approach, the power-law decay exponent of E_K for runs
// that stay circular, and transient states (local minima of E_K on plateaus of the total energy).
// Pure functions of sampled series: t is increasing (µs in practice; results are in t's unit) and
// every y has t.size() entries, else std::invalid_argument. Fit method: docs/analysis.md.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

namespace ibrod::diagnostics {

/// Ordinary least-squares line y ≈ intercept + slope·x over the window [first, first + count) of
/// the caller's series.
struct LineFit {
  double slope = 0;
  double intercept = 0;
  double r2 = 0;                ///< coefficient of determination; 1 for an exact line (also for a
                                ///< constant y, which the line fits exactly)
  double max_abs_residual = 0;  ///< max |y − fit| over the window, in y's unit
  std::size_t first = 0;        ///< index of the window's first sample
  std::size_t count = 0;        ///< samples in the window (≥ 2)
};

/// Least-squares line through (x_i, y_i), all of them; needs ≥ 2 points and x not all equal
/// (std::invalid_argument otherwise). first = 0, count = x.size().
LineFit fit_line(std::span<const double> x, std::span<const double> y);

/// How the final window of a fit is chosen.
struct WindowOptions {
  double tolerance = 0.02;     ///< largest admissible |residual| in the window, y's unit (for
                               ///< ln E: 0.02 = 2 % of E)
  std::size_t min_points = 5;  ///< shortest window
};

/// A fit on the longest final window [i, n) of (x, y) on which y is a line in x: max |residual|
/// ≤ tolerance. Window lengths grow from min_points geometrically (×1.05) until one fails, then
/// the boundary is bisected between the last length that passed and the first that failed, so the
/// cost is O(n log n). If even the shortest window fails, that window is returned (its
/// max_abs_residual then exceeds the tolerance: the caller reports it). nullopt when n <
/// min_points. x, y finite.
std::optional<LineFit> fit_final_linear_window(std::span<const double> x, std::span<const double> y,
                                               const WindowOptions& opt = {});

/// Writhe convergence time: the largest t at which |Wr(t) − Wr(∞)| > delta, with Wr(∞) the last
/// sample and Wr(t) linear between samples (so the answer is the last crossing of the band
/// Wr(∞) ± delta, between samples). t.front() when the whole series lies inside the band.
/// Empty series: std::invalid_argument.
double writhe_convergence_time(std::span<const double> t, std::span<const double> writhe,
                               double delta = 0.01);

/// τ of E_K ∝ exp(−2t/τ) fitted on the final approach.
struct ExponentialFit {
  double tau = 0;  ///< relaxation time, t's unit: τ = −2 / slope
  LineFit line;    ///< the fit of ln E_K against t; window indices refer to the input series
};

/// Fits ln E_K = a − 2t/τ (log-linear least squares) on the longest final window where ln E_K is
/// linear to opt.tolerance (fit_final_linear_window), within the final run of positive E_K.
/// nullopt when fewer than opt.min_points final samples are positive, or when E_K does not
/// decay there (slope ≥ 0).
std::optional<ExponentialFit> relaxation_time(std::span<const double> t,
                                              std::span<const double> kinetic,
                                              const WindowOptions& opt = {});

/// τ of E_K ∝ exp(−2t/τ) fitted (least squares in ln E_K) on every sample with t ≥ t_start and
/// E_K > 0 — the approach after the last contact formed (docs/analysis.md). nullopt with fewer
/// than min_points such samples or when E_K does not decay there (slope ≥ 0).
std::optional<ExponentialFit> relaxation_time_from(std::span<const double> t,
                                                   std::span<const double> kinetic, double t_start,
                                                   std::size_t min_points = 5);

/// τ(t) = −2 / (d ln E_K / dt) over one window of the series.
struct LocalRelaxation {
  double t_start = 0, t_end = 0;  ///< the window [t_start, t_end), t's unit
  double tau = 0;                 ///< −2/slope of ln E_K there; negative where E_K grows
  std::size_t points = 0;
};

/// τ(t) on consecutive windows [t_0 + k·width, t_0 + (k+1)·width) that hold at least 3 samples
/// with E_K > 0 (others are skipped); slope 0 (flat E_K) gives no entry. width > 0.
std::vector<LocalRelaxation> local_relaxation_times(std::span<const double> t,
                                                    std::span<const double> kinetic, double width);

/// When a sampled count stops changing: the time of the first sample after its last change,
/// t.front() if it never changes. t and count the same size, not empty.
double settled_time(std::span<const double> t, std::span<const int> count);

/// Exponent p of E_K ∝ t^p (p < 0 for a decay), fitted as ln E_K against ln t on the longest final
/// window where that is a line to opt.tolerance, within the final run of samples with t > 0 and
/// E_K > 0. nullopt when fewer than opt.min_points such samples.
struct PowerLawFit {
  double exponent = 0;
  LineFit line;  ///< the fit of ln E_K against ln t; window indices refer to the input series
};
std::optional<PowerLawFit> power_law_exponent(std::span<const double> t,
                                              std::span<const double> kinetic,
                                              const WindowOptions& opt = {});

/// How transient states are recognised.
struct TransientOptions {
  double min_rise = 2.0;          ///< E_K must rise by at least this factor on both sides of
                                  ///< the minimum (before the series goes lower again)
  double plateau_fraction = 0.2;  ///< |dE_total/dt| at the minimum at most this fraction of its
                                  ///< largest value between the E_K peaks on either side
};

/// A transient state: the rod lingers near an unstable equilibrium.
struct Transient {
  std::size_t index = 0;     ///< sample of the E_K minimum
  double time = 0;           ///< t at the minimum
  double kinetic = 0;        ///< E_K at the minimum
  double total = 0;          ///< E_total at the minimum (the plateau's energy)
  double plateau_start = 0;  ///< t where the plateau (|dE_total/dt| below the threshold around
  double plateau_end = 0;    ///< the minimum) begins and ends
};

/// Local minima of E_K (only samples with E_K > 0 count) whose prominence in E_K is at least
/// opt.min_rise on both sides and at which the total energy is on a plateau: |dE_total/dt|
/// (central differences) at most opt.plateau_fraction of its largest value between the E_K
/// peaks that bracket the minimum. In time order.
std::vector<Transient> transients(std::span<const double> t, std::span<const double> kinetic,
                                  std::span<const double> total, const TransientOptions& opt = {});

}  // namespace ibrod::diagnostics
