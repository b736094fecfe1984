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
    for (int k = 0; k < rod::half_points(rod.n, rod.closed); ++k)
      b = std::min(b, rod.b_k[k].minCoeff());
  return std::max(0.5, 7.0 * std::sqrt(thermal_kT * rod.ds / b) / rod.ds);
}

std::string rod_problem(const rod::RodState& s, double ds, double tolerance, bool closed) {
  return rod_problem(s.X, s.D, ds, tolerance, closed);
}

std::string rod_problem(std::span<const Vec3> X, std::span<const Mat3> D, double ds,
                        double tolerance, bool closed) {
  const double lo = std::max(0.05, 1.0 - tolerance), hi = 1.0 + tolerance;
  const int n = int(X.size());
  char buf[256];
  for (int k = 0; k < n; ++k) {
    if (!X[k].allFinite()) {
      std::snprintf(buf, sizeof buf, "the position of point %d is not finite (%g, %g, %g) Å", k,
                    X[k][0], X[k][1], X[k][2]);
      return buf;
    }
    if (!D[k].allFinite()) return "the triad of point " + std::to_string(k) + " is not finite";
  }
  for (int k = 0; k < rod::half_points(n, closed); ++k) {
    const int k1 = k + 1 == n ? 0 : k + 1;
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

std::string state_problem(const rod::RodState& s, int n, double ds, bool closed) {
  if (s.size() != n || int(s.D.size()) != n)
    return std::to_string(s.size()) + " positions and " + std::to_string(s.D.size()) +
           " triads; the rod has " + std::to_string(n) + " points (rod.base_pairs)";
  if (std::string bad = rod_problem(s, ds, 0.5, closed); !bad.empty()) return bad;
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
    const int prev = k > 0 ? k - 1 : closed ? n - 1 : 0;
    const int next = k + 1 < n ? k + 1 : closed ? 0 : n - 1;
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
int total_points(std::span<const rod::RodParams> rods) {
  int n = 0;
  for (const rod::RodParams& r : rods) n += r.n;
  return n;
}
}  // namespace

std::string rods_problem(std::span<const rod::RodParams> rods, const rod::RodState& s,
                         std::span<const double> tolerances) {
  if (rods.size() == 1) return rod_problem(s, rods[0].ds, tolerances[0], rods[0].closed);
  const int n = total_points(rods);
  if (s.size() != n || int(s.D.size()) != n)
    return std::to_string(s.size()) + " positions and " + std::to_string(s.D.size()) +
           " triads; the rods have " + std::to_string(n) + " points";
  const std::span<const Vec3> X(s.X);
  const std::span<const Mat3> D(s.D);
  std::size_t offset = 0;
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const std::size_t m = std::size_t(rods[r].n);
    if (std::string bad = rod_problem(X.subspan(offset, m), D.subspan(offset, m), rods[r].ds,
                                      tolerances[r], rods[r].closed);
        !bad.empty())
      return "rod " + std::to_string(r) + ": " + bad;
    offset += m;
  }
  return {};
}

std::string rods_state_problem(std::span<const rod::RodParams> rods, const rod::RodState& s,
                               double box) {
  if (rods.size() == 1) return state_problem(s, rods[0].n, rods[0].ds, rods[0].closed);
  const int n = total_points(rods);
  if (s.size() != n || int(s.D.size()) != n)
    return std::to_string(s.size()) + " positions and " + std::to_string(s.D.size()) +
           " triads; the rods have " + std::to_string(n) + " points together";
  rod::RodState one;
  const std::vector<rod::RodRange> ranges = rod::ranges_of(rods);
  for (std::size_t r = 0; r < rods.size(); ++r) {
    rod::extract(s, ranges[r], one);
    if (std::string bad = state_problem(one, rods[r].n, rods[r].ds, rods[r].closed); !bad.empty())
      return "rod " + std::to_string(r) + ": " + bad;
  }
  // two rods must not start on top of each other (coincident charges, crossed hard cores)
  for (std::size_t a = 0; a < rods.size(); ++a)
    for (std::size_t b = a + 1; b < rods.size(); ++b) {
      const double min_d = 0.5 * std::min(rods[a].ds, rods[b].ds);
      for (int i = 0; i < ranges[a].n; ++i)
        for (int j = 0; j < ranges[b].n; ++j) {
          Vec3 v = s.X[ranges[a].offset + i] - s.X[ranges[b].offset + j];
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
            return buf;
          }
        }
    }
  return {};
}

}  // namespace ibrod::sim
