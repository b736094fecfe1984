#include "sim/rod_problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/units.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::sim {

double spacing_tolerance(const rod::RodParams& rod, double thermal_kT) {
  if (!(thermal_kT > 0)) return 0.5;
  double b = rod.b.minCoeff();  // the softest shear or stretch (per link: rod.moduli_file)
  if (!rod.b_k.empty())         // the links in use (an open rod's last row is not)
    for (int k = 0; k < rod::links(rod); ++k) b = std::min(b, rod.b_k[k].minCoeff());
  return std::max(0.5, 7.0 * std::sqrt(thermal_kT * rod.ds / b) / rod.ds);
}

namespace {
// A ring of n points Δs = ds apart (RodRange's default kind), at the start of its state.
rod::RodRange ring(int n, double ds) {
  rod::RodRange g{0, n};
  g.ds = ds;
  return g;
}
}  // namespace

std::string rod_problem(const rod::RodState& s, double ds, double tolerance) {
  return rod_problem(s.X, s.D, ring(s.size(), ds), tolerance);
}

std::string rod_problem(std::span<const Vec3> X_all, std::span<const Mat3> D_all,
                        const rod::RodRange& g, double tolerance) {
  const double lo = std::max(0.05, 1.0 - tolerance), hi = 1.0 + tolerance;
  const std::size_t at = std::size_t(g.offset), m = std::size_t(g.n);
  const std::span<const Vec3> X = X_all.subspan(at, m);
  const std::span<const Mat3> D = D_all.subspan(at, m);
  const double ds = g.ds;
  const int n = g.n;
  char buf[256];
  for (int k = 0; k < n; ++k) {
    if (!X[k].allFinite()) {
      std::snprintf(buf, sizeof buf, "the position of point %d is not finite (%g, %g, %g) Å", k,
                    X[k][0], X[k][1], X[k][2]);
      return buf;
    }
    if (!D[k].allFinite()) return "the triad of point " + std::to_string(k) + " is not finite";
  }
  for (int k = 0; k < rod::links(g); ++k) {
    const int k1 = rod::after(g, k);
    const double r = (X[k1] - X[k]).norm() / ds;
    if (!(r >= lo && r <= hi)) {
      std::snprintf(buf, sizeof buf,
                    "the spacing of points %d and %d is %.4g Δs (allowed: %.4g to %.4g Δs)", k, k1,
                    r, lo, hi);
      return buf;
    }
  }
  for (int k = 0; k < n; ++k) {
    const double e = (D[k].transpose() * D[k] - Mat3::Identity()).cwiseAbs().maxCoeff();
    if (!(e <= 1e-3)) {
      std::snprintf(
          buf, sizeof buf,
          "the triad of point %d is off orthonormal by %.3g (max |DᵀD − I|; allowed 1e-3)", k, e);
      return buf;
    }
  }
  return {};
}

std::string state_problem(const rod::RodState& s, int n, double ds) {
  return state_problem(s, ring(n, ds));
}

std::string state_problem(const rod::RodState& s, const rod::RodRange& rod_range) {
  rod::RodRange g = rod_range;  // s holds the rod alone
  g.offset = 0;
  const int n = g.n;
  if (s.size() != n || int(s.D.size()) != n)
    return std::to_string(s.size()) + " positions and " + std::to_string(s.D.size()) +
           " triads; the rod has " + std::to_string(n) + " points (rod.base_pairs)";
  if (std::string bad = rod_problem(s.X, s.D, g, 0.5); !bad.empty()) return bad;
  for (int k = 0; k < n; ++k)
    if (const double det = s.D[k].determinant(); !(det > 0)) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "the triad of point %d is left-handed (det D = %.3g); D³ must be D¹ × D²", k,
                    det);
      return buf;
    }
  // D³ along the rod: an orthonormal triad with its rows and columns swapped passes the checks
  // above, and the run then blows up at its first step
  for (int k = 0; k < n; ++k) {
    const int prev = rod::point_before(g, k), next = rod::point_after(g, k);
    const Vec3 t = s.X[next] - s.X[prev];  // central; one-sided at an open rod's ends
    const double c = t.dot(s.D[k].col(2)) / t.norm();
    if (!(c >= kMinTangentCosine)) {
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "the triad of point %d has D³ %.0f° off the rod's tangent (at most %.0f° "
                    "allowed: D³ points along the rod, from point k toward point k + 1; are D's "
                    "rows and columns swapped?)",
                    k, std::acos(std::clamp(c, -1.0, 1.0)) * 180 / M_PI,
                    std::acos(kMinTangentCosine) * 180 / M_PI);
      return buf;
    }
  }
  return {};
}

namespace {
// What is wrong with a state whose count of points is not the rods' total, "" if nothing.
std::string count_problem(std::span<const rod::RodParams> rods, const rod::RodState& s) {
  const int n = rod::total_points(rods);
  if (s.size() == n && int(s.D.size()) == n) return {};
  return std::to_string(s.size()) + " positions and " + std::to_string(s.D.size()) + " triads; " +
         (rod::names_rods(rods) ? "the rods have " + std::to_string(n) + " points together"
                                : "the rod has " + std::to_string(n) + " points (rod.base_pairs)");
}
}  // namespace

std::string rods_problem(std::span<const rod::RodParams> rods, const rod::RodState& s,
                         std::span<const double> tolerances) {
  if (std::string bad = count_problem(rods, s); !bad.empty()) return bad;
  const std::span<const Vec3> X(s.X);
  const std::span<const Mat3> D(s.D);
  std::string bad;  // the first rod's problem
  rod::for_each_range(rods, [&](std::size_t r, const rod::RodRange& g) {
    if (!bad.empty()) return;
    if (std::string b = rod_problem(X, D, g, tolerances[r]); !b.empty())
      bad = rod::message_prefix(rods, r) + b;
  });
  return bad;
}

std::string rods_state_problem(std::span<const rod::RodParams> rods, const rod::RodState& s,
                               double box) {
  if (std::string bad = count_problem(rods, s); !bad.empty()) return bad;
  const std::vector<rod::RodRange> ranges = rod::ranges_of(rods);
  std::string bad;  // the first problem found
  rod::RodState one;
  rod::for_each_rod(ranges, [&](std::size_t r, const rod::RodRange& g) {
    if (!bad.empty()) return;
    rod::extract(s, g, one);
    if (std::string b = state_problem(one, g); !b.empty()) bad = rod::message_prefix(ranges, r) + b;
  });
  // two rods must not start on top of each other (coincident charges, crossed hard cores)
  rod::for_each_pair(ranges, [&](std::size_t a, std::size_t b) {
    const rod::RodRange &ga = ranges[a], &gb = ranges[b];
    const double min_d = 0.5 * std::min(ga.ds, gb.ds);
    for (int i = 0; i < ga.n && bad.empty(); ++i)
      for (int j = 0; j < gb.n && bad.empty(); ++j) {
        Vec3 v = s.X[ga.offset + i] - s.X[gb.offset + j];
        // the box is periodic: a rod on another's periodic image lies on it in the fluid
        if (box > 0) v -= box * (v / box).array().round().matrix();
        const double d = v.norm();
        if (!(d >= min_d)) {
          char buf[400];
          std::snprintf(buf, sizeof buf,
                        "rods %zu and %zu overlap: point %d of rod %zu and point %d of rod %zu "
                        "are %.3g Å apart%s (at least half a rise, %.3g Å, needed; place the "
                        "rods apart with rod.offset_A)",
                        a, b, i, a, j, b, d / units::angstrom,
                        box > 0 ? " in the periodic box" : "", min_d / units::angstrom);
          bad = buf;
        }
      }
  });
  return bad;
}

}  // namespace ibrod::sim
