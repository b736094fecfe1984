// Hard-core repulsion between non-neighbouring rod segments, MODEL (2.17–2.18); Lim, Kim &
// Swigon 2011. The paper's contact of mutual closest material points is taken segment by segment.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "interactions/cell_list.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions {

namespace {
inline double clamp01(double x) { return std::clamp(x, 0.0, 1.0); }
}  // namespace

SegmentContact closest_points(const Vec3& P0, const Vec3& P1, const Vec3& Q0, const Vec3& Q1) {
  const Vec3 d1 = P1 - P0, d2 = Q1 - Q0, r = P0 - Q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm();
  const double b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {  // two points
  } else if (a <= 0) {     // P is a point: project it on Q
    t = clamp01(f / e);
  } else if (e <= 0) {  // Q is a point: project it on P
    s = clamp01(-c / a);
  } else {
    const Vec3 nrm = d1.cross(d2);
    const double denom = nrm.squaredNorm();  // = ae − b², without its cancellation
    if (denom > 1e-20 * a * e) {
      // closest points of the two lines, s = (bf − ce)/(ae − b²), clamped to P
      s = clamp01(nrm.cross(d2).dot(r) / denom);
    } else {
      // parallel: the minimisers fill the overlap of P with Q's projection on P; take its middle
      const double s_q0 = -c / a, s_q1 = (b - c) / a;  // Q0, Q1 projected on P's parameter
      const double lo = std::max(0.0, std::min(s_q0, s_q1));
      const double hi = std::min(1.0, std::max(s_q0, s_q1));
      s = lo <= hi ? 0.5 * (lo + hi) : (std::max(s_q0, s_q1) < 0.0 ? 0.0 : 1.0);
    }
    // the point of Q nearest P(s); if it is off Q, clamp it and re-project onto P
    t = (b * s + f) / e;
    if (t < 0) {
      t = 0;
      s = clamp01(-c / a);
    } else if (t > 1) {
      t = 1;
      s = clamp01((b - c) / a);
    }
  }
  SegmentContact k;
  k.s = s;
  k.t = t;
  k.sep = (P0 + s * d1) - (Q0 + t * d2);
  k.d = k.sep.norm();
  return k;
}

double steric_pair(double D, double g, const Vec3& P0, const Vec3& P1, const Vec3& Q0,
                   const Vec3& Q1, std::array<Vec3, 4>& f) {
  const SegmentContact k = closest_points(P0, P1, Q0, Q1);
  if (!(k.d < D)) {
    for (Vec3& v : f) v.setZero();
    return 0;
  }
  Vec3 u;
  if (k.d > 0) {
    u = k.sep / k.d;
  } else {  // the segments touch: push along their common normal (any normal if parallel)
    Vec3 nrm = (P1 - P0).cross(Q1 - Q0);
    if (nrm.squaredNorm() == 0) nrm = (P1 - P0).unitOrthogonal();
    u = nrm.normalized();
  }
  const double overlap = D - k.d;
  const Vec3 fu = (g * overlap) * u;  // MODEL (2.18): g (D − d) along P(s) − Q(t)
  f[0] = (1 - k.s) * fu;
  f[1] = k.s * fu;
  f[2] = -(1 - k.t) * fu;
  f[3] = -k.t * fu;
  return 0.5 * g * overlap * overlap;  // MODEL (2.17)
}

std::vector<rod::RodRange> steric_rods(const StericParams& p, int n) {
  if (!p.rods.empty()) return p.rods;
  return {{0, n, p.closed, p.ds}};
}

void Steric::build_segments(int n) const {
  if (seg_built_for_ == n) return;
  std::vector<rod::RodRange> chains = steric_rods(p_, n);
  int count = 0;
  for (const rod::RodRange& c : chains) {
    if (c.offset != count || c.n < 0)
      throw std::invalid_argument("Steric: the rods' ranges must cover the points in order");
    count += c.n;
  }
  if (count != n)
    throw std::invalid_argument("Steric: the rods have " + std::to_string(count) +
                                " points, the state " + std::to_string(n));
  seg_a_.clear();
  seg_b_.clear();
  seg_chain_.clear();
  seg_pos_.clear();
  for (std::size_t r = 0; r < chains.size(); ++r) {
    const rod::RodRange& c = chains[r];
    if (c.n < 2) continue;
    for (int k = 0; k < rod::links(c); ++k) {  // a ring's last one X_{n−1} → X_0
      seg_a_.push_back(c.offset + k);
      seg_b_.push_back(c.offset + (k + 1) % c.n);
      seg_chain_.push_back(int(r));
      seg_pos_.push_back(k);
    }
  }
  chains_ = std::move(chains);
  seg_built_for_ = n;
}

// Whether segments k and l are a pair: different rods always; the same rod when more than 2D
// apart along it (closed: the cyclic index distance; open: |k − l|).
bool Steric::far_along_rod(int k, int l) const {
  if (seg_chain_[k] != seg_chain_[l]) return true;
  const rod::RodRange& c = chains_[seg_chain_[k]];
  return rod::arc_separation(c, seg_pos_[k], seg_pos_[l]) * c.ds > 2 * p_.diameter;
}

// Segment pair k, l: adds the forces on their end points into F (indexed by point); returns the
// energy.
double Steric::segment_pair(std::span<const Vec3> X, int k, int l, Vec3* F) const {
  const int k0 = seg_a_[k], k1 = seg_b_[k], l0 = seg_a_[l], l1 = seg_b_[l];
  std::array<Vec3, 4> f;
  const double E = steric_pair(p_.diameter, p_.stiffness, X[k0], X[k1], X[l0], X[l1], f);
  if (E > 0) {
    F[k0] += f[0];
    F[k1] += f[1];
    F[l0] += f[2];
    F[l1] += f[3];
  }
  return E;
}

Steric::Steric(const StericParams& p, int n) : p_(p) {
  cells_.order.reserve(n);
  cells_.cell.reserve(n);
  cells_.x.reserve(n);
  mid_.reserve(n);
  build_segments(n);
}

double Steric::accumulate(std::span<const Vec3> X, std::span<Vec3> F) {
  used_cells_ = false;
  const int n = int(X.size());
  if (!p_.enabled || n < 2 || !(p_.diameter > 0)) return 0;
  build_segments(n);
  // midpoints and the longest segment: closest distance < D ⇒ midpoints < D + L_max apart
  const int ns = int(seg_a_.size());
  mid_.resize(ns);
  double lmax2 = 0;
  for (int k = 0; k < ns; ++k) {
    const Vec3& a = X[seg_a_[k]];
    const Vec3& b = X[seg_b_[k]];
    mid_[k] = 0.5 * (a + b);
    lmax2 = std::max(lmax2, (b - a).squaredNorm());
  }
  const double reach = p_.diameter + std::sqrt(lmax2);
  const double reach2 = reach * reach;
  const detail::CellGrid g = detail::make_grid(mid_, reach, 4 * ns + 64);
  used_cells_ = !g.trivial();
  if (!used_cells_) {
    // the loop runs over n (the force buffers' size); segments number at most n
    return detail::parallel_pairs(n, F, thread_F_, thread_E_, [&](int k, Vec3* Ft, double& E) {
      for (int l = k + 1; l < ns; ++l)
        if ((mid_[k] - mid_[l]).squaredNorm() < reach2 && far_along_rod(k, l))
          E += segment_pair(X, k, l, Ft);
    });
  }
  detail::bin(g, mid_, cells_);
  const detail::CellScratch& c = cells_;
  return detail::parallel_pairs(n, F, thread_F_, thread_E_, [&](int a, Vec3* Ft, double& E) {
    if (a >= ns) return;  // open rods: fewer segments than force slots
    const int k = c.order[a];
    detail::for_each_partner(g, c, a, [&](int b) {
      const int l = c.order[b];
      if ((c.x[a] - c.x[b]).squaredNorm() < reach2 && far_along_rod(k, l))
        E += segment_pair(X, std::min(k, l), std::max(k, l), Ft);
    });
  });
}

double Steric::accumulate_direct(std::span<const Vec3> X, std::span<Vec3> F) const {
  if (!p_.enabled) return 0;
  const int n = int(X.size());
  if (n < 2) return 0;
  build_segments(n);
  double E = 0;
  const int ns = int(seg_a_.size());
  for (int k = 0; k < ns; ++k)
    for (int l = k + 1; l < ns; ++l)
      if (far_along_rod(k, l)) E += segment_pair(X, k, l, F.data());
  return E;
}

double Steric::energy(std::span<const Vec3> X) const {
  if (!p_.enabled) return 0;
  const int n = int(X.size());
  if (n < 2) return 0;
  build_segments(n);
  double E = 0;
  std::array<Vec3, 4> f;
  const int ns = int(seg_a_.size());
  for (int k = 0; k < ns; ++k)
    for (int l = k + 1; l < ns; ++l)
      if (far_along_rod(k, l))
        E += steric_pair(p_.diameter, p_.stiffness, X[seg_a_[k]], X[seg_b_[k]], X[seg_a_[l]],
                         X[seg_b_[l]], f);
  return E;
}

}  // namespace ibrod::interactions
