// Debye–Hückel electrostatics between rod points, MODEL (2.19–2.22); Lim, Kim & Swigon 2011.
#include <cmath>
#include <numbers>

#include "core/units.hpp"
#include "interactions/cell_list.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions {

DebyeHuckel debye_huckel(double charge_e, double dielectric, double salt_M) {
  DebyeHuckel law;
  law.A = charge_e * charge_e / (4 * std::numbers::pi * units::vacuum_permittivity * dielectric);
  law.kappa = units::debye_kappa(salt_M);
  return law;
}

ElectroParams electro_params(bool enabled, double charge_e, double dielectric, double salt_M,
                             double cutoff_debye) {
  ElectroParams p;
  p.enabled = enabled;
  p.law = debye_huckel(charge_e, dielectric, salt_M);
  p.cutoff = p.law.kappa > 0 ? cutoff_debye / p.law.kappa : 0.0;
  return p;
}

namespace {

/// One pair i, j (d² = |Δ|², Δ = X_i − X_j, within the cutoff): adds the force on i to fi and
/// subtracts it from fj (Newton's third law), returns the shifted pair energy.
inline double pair(const DebyeHuckel& law, double e_shift, const Vec3& delta, double d2, Vec3& fi,
                   Vec3& fj) {
  const DebyeHuckel::Terms t = law.eval(d2);
  const Vec3 f = t.force_over_d * delta;
  fi += f;
  fj -= f;
  return t.energy - e_shift;
}

}  // namespace

Electrostatics::Electrostatics(const ElectroParams& p, int n) : p_(p) {
  if (p_.cutoff > 0) e_shift_ = p_.law.energy(p_.cutoff);
  cells_.order.reserve(n);
  cells_.cell.reserve(n);
  cells_.x.reserve(n);
}

double Electrostatics::accumulate(std::span<const Vec3> X, std::span<Vec3> F) {
  used_cells_ = false;
  const int n = int(X.size());
  if (!p_.enabled || n < 2) return 0;
  const double rc2 = p_.cutoff > 0 ? p_.cutoff * p_.cutoff : HUGE_VAL;
  const DebyeHuckel law = p_.law;
  const double shift = e_shift_;

  // cells of edge ≥ rc: pairs within rc are in the same or adjacent cells; when every cell
  // neighbours every other (≤ 2 per axis: rc above about half the rod's extent) the list could
  // not prune anything and the direct sum runs
  detail::CellGrid g;
  if (p_.cutoff > 0) {
    g = detail::make_grid(X, p_.cutoff, 4 * n + 64);
    used_cells_ = !g.trivial();
  }
  // The bodies copy what they read into locals: through the lambda's captured references the
  // compiler would have to reload them after every store into the force buffer (aliasing).
  if (!used_cells_) {
    return detail::parallel_pairs(n, F, thread_F_, thread_E_, [&](int i, Vec3* Ft, double& E) {
      const DebyeHuckel lw = law;
      const double r2 = rc2, sh = shift;
      const Vec3* x = X.data();
      const Vec3 xi = x[i];
      Vec3 fi = Vec3::Zero();
      double e = 0;
      for (int j = i + 1; j < n; ++j) {
        const Vec3 delta = xi - x[j];
        const double d2 = delta.squaredNorm();
        if (d2 <= r2) e += pair(lw, sh, delta, d2, fi, Ft[j]);
      }
      Ft[i] += fi;
      E += e;
    });
  }
  detail::bin(g, X, cells_);
  const detail::CellScratch& c = cells_;
  return detail::parallel_pairs(n, F, thread_F_, thread_E_, [&](int a, Vec3* Ft, double& E) {
    const DebyeHuckel lw = law;
    const double r2 = rc2, sh = shift;
    const Vec3* x = c.x.data();
    const int* order = c.order.data();
    const Vec3 xa = x[a];
    Vec3 fa = Vec3::Zero();
    double e = 0;
    detail::for_each_partner(g, c, a, [&](int b) {
      const Vec3 delta = xa - x[b];
      const double d2 = delta.squaredNorm();
      if (d2 <= r2) e += pair(lw, sh, delta, d2, fa, Ft[order[b]]);
    });
    Ft[order[a]] += fa;
    E += e;
  });
}

double Electrostatics::accumulate_direct(std::span<const Vec3> X, std::span<Vec3> F) const {
  if (!p_.enabled) return 0;
  const int n = int(X.size());
  const double rc2 = p_.cutoff > 0 ? p_.cutoff * p_.cutoff : HUGE_VAL;
  double E = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const Vec3 delta = X[i] - X[j];
      const double d2 = delta.squaredNorm();
      if (d2 <= rc2) E += pair(p_.law, e_shift_, delta, d2, F[i], F[j]);
    }
  return E;
}

double Electrostatics::energy(std::span<const Vec3> X) const {
  if (!p_.enabled) return 0;
  const int n = int(X.size());
  const double rc2 = p_.cutoff > 0 ? p_.cutoff * p_.cutoff : HUGE_VAL;
  double E = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double d2 = (X[i] - X[j]).squaredNorm();
      if (d2 <= rc2) E += p_.law.energy(std::sqrt(d2)) - e_shift_;
    }
  return E;
}

}  // namespace ibrod::interactions
