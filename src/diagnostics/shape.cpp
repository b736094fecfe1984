// Shape of a closed rod: crossings, lobes, two-ply runs, contacts and the class (shape.hpp;
// criteria in docs/analysis.md "Shapes").
#include "diagnostics/shape.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include "diagnostics/topology.hpp"

namespace ibrod::diagnostics {

namespace {

int cyclic_distance(int i, int j, int n) {
  const int d = std::abs(i - j) % n;
  return std::min(d, n - d);
}

/// d wrapped into (−n/2, n/2].
int wrap(int d, int n) {
  d %= n;
  if (d > n / 2) d -= n;
  if (d <= -((n + 1) / 2)) d += n;
  return d;
}

double orient(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// Local maxima of the cyclic series r whose topographic prominence (height above the higher of
/// the two lowest points between it and the nearest higher sample on either side) is at least
/// `min_prominence`.
int prominent_maxima(const std::vector<double>& r, double min_prominence) {
  const int n = int(r.size());
  int count = 0;
  for (int k = 0; k < n; ++k) {
    const double rk = r[k];
    if (!(rk >= r[(k + n - 1) % n] && rk > r[(k + 1) % n])) continue;
    double low_left = rk, low_right = rk;
    for (int s = 1; s < n; ++s) {  // left until higher
      const double v = r[(k - s % n + n) % n];
      if (v > rk) break;
      low_left = std::min(low_left, v);
    }
    for (int s = 1; s < n; ++s) {  // right until higher (or equal: plateaus count once)
      const double v = r[(k + s) % n];
      if (v >= rk) break;
      low_right = std::min(low_right, v);
    }
    if (rk - std::max(low_left, low_right) >= min_prominence) ++count;
  }
  return count;
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

}  // namespace

const char* shape_class_name(ShapeClass c) {
  switch (c) {
    case ShapeClass::circle:
      return "circle";
    case ShapeClass::figure8:
      return "figure-8";
    case ShapeClass::plectonemic:
      return "plectonemic";
    case ShapeClass::toroidal:
      return "toroidal";
    case ShapeClass::other:
      return "other";
  }
  return "other";
}

std::vector<Vec3> hemisphere_directions(int n) {
  if (n < 1) throw std::invalid_argument("hemisphere_directions: n must be positive");
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<Vec3> u(n);
  for (int k = 0; k < n; ++k) {
    const double z = (k + 0.5) / n;
    const double r = std::sqrt(1.0 - z * z);
    u[k] = Vec3(r * std::cos(golden * k), r * std::sin(golden * k), z);
  }
  return u;
}

int projected_crossings(std::span<const Vec3> X, const Vec3& direction) {
  const int n = int(X.size());
  if (n < 4) return 0;
  // an orthonormal basis (e1, e2) of the plane normal to the direction
  const Vec3 u = direction.normalized();
  const Vec3 helper = std::abs(u.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 e1 = u.cross(helper).normalized();
  const Vec3 e2 = u.cross(e1);
  std::vector<Eigen::Vector2d> P(n);
  for (int k = 0; k < n; ++k) P[k] = {X[k].dot(e1), X[k].dot(e2)};
  // edges sorted by their smallest x; each is compared with the later ones its x-range meets
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto xmin = [&](int k) { return std::min(P[k].x(), P[(k + 1) % n].x()); };
  auto xmax = [&](int k) { return std::max(P[k].x(), P[(k + 1) % n].x()); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return xmin(a) < xmin(b); });
  int crossings = 0;
  for (int a = 0; a < n; ++a) {
    const int i = order[a];
    const double hi = xmax(i);
    const Eigen::Vector2d &p0 = P[i], &p1 = P[(i + 1) % n];
    for (int b = a + 1; b < n && xmin(order[b]) <= hi; ++b) {
      const int j = order[b];
      if (cyclic_distance(i, j, n) < 2) continue;  // adjacent edges share a vertex
      const Eigen::Vector2d &q0 = P[j], &q1 = P[(j + 1) % n];
      if (orient(p0, p1, q0) * orient(p0, p1, q1) < 0 &&
          orient(q0, q1, p0) * orient(q0, q1, p1) < 0)
        ++crossings;
    }
  }
  return crossings;
}

double segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  // closest points of two segments (Ericson, Real-Time Collision Detection, 5.1.9)
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) return r.norm();
  if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return (p0 + s * d1 - (q0 + t * d2)).norm();
}

std::vector<std::vector<std::pair<int, int>>> contact_clusters(std::span<const Vec3> X,
                                                               double distance,
                                                               double min_separation) {
  const int n = int(X.size());
  std::vector<std::vector<std::pair<int, int>>> clusters;
  if (n < 4) return clusters;
  const double h = mean_spacing(X);
  double longest = 0;
  for (int k = 0; k < n; ++k) longest = std::max(longest, (X[(k + 1) % n] - X[k]).norm());
  const int m_min = std::max(2, int(std::ceil(min_separation / h - 1e-9)));
  // contact pairs (edge i < edge j), by a vertex-distance prefilter and the segment distance
  std::vector<std::pair<int, int>> pairs;
  std::unordered_map<std::int64_t, int> index;
  const double reach = distance + 2 * longest;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (cyclic_distance(i, j, n) < m_min) continue;
      if ((X[i] - X[j]).squaredNorm() > reach * reach) continue;
      if (segment_distance(X[i], X[(i + 1) % n], X[j], X[(j + 1) % n]) >= distance) continue;
      index[std::int64_t(i) * n + j] = int(pairs.size());
      pairs.emplace_back(i, j);
    }
  // clusters: neighbouring pairs (each index within 1, cyclically) joined
  UnionFind uf(int(pairs.size()));
  for (int p = 0; p < int(pairs.size()); ++p)
    for (int a = -1; a <= 1; ++a)
      for (int b = -1; b <= 1; ++b) {
        int i = (pairs[p].first + a + n) % n, j = (pairs[p].second + b + n) % n;
        if (i > j) std::swap(i, j);
        const auto it = index.find(std::int64_t(i) * n + j);
        if (it != index.end()) uf.unite(p, it->second);
      }
  std::unordered_map<int, int> root_to_cluster;
  for (int p = 0; p < int(pairs.size()); ++p) {
    const int root = uf.find(p);
    auto [it, fresh] = root_to_cluster.emplace(root, int(clusters.size()));
    if (fresh) clusters.emplace_back();
    clusters[it->second].push_back(pairs[p]);
  }
  std::sort(clusters.begin(), clusters.end());
  return clusters;
}

Shape analyze_shape(std::span<const Vec3> X, const ShapeOptions& opt) {
  const int n = int(X.size());
  if (n < 8) throw std::invalid_argument("analyze_shape: needs at least 8 points");
  if (!(opt.contact_distance_A > 0) || opt.directions < 1)
    throw std::invalid_argument("analyze_shape: contact distance and directions must be positive");
  const double dc = opt.contact_distance_A;
  const double s_min = opt.min_separation_A > 0 ? opt.min_separation_A : 2 * dc;
  const double l_min = opt.min_interwound_A > 0 ? opt.min_interwound_A : 3 * dc;
  const double h = mean_spacing(X);
  const int m_min = std::max(2, int(std::ceil(s_min / h - 1e-9)));
  Shape s;

  // crossings: the fewest over the directions
  s.crossings = std::numeric_limits<int>::max();
  std::unordered_map<int, int> histogram;
  for (const Vec3& u : hemisphere_directions(opt.directions)) {
    const int c = projected_crossings(X, u);
    ++histogram[c];
    if (c < s.crossings) {
      s.crossings = c;
      s.direction = u;
    }
  }
  int most = 0;
  for (const auto& [c, count] : histogram)
    if (count > most || (count == most && c < s.crossings_mode)) {
      most = count;
      s.crossings_mode = c;
    }

  // lobes: prominent maxima of the distance from the centroid along the rod
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& x : X) centroid += x;
  centroid /= n;
  std::vector<double> r(n);
  for (int k = 0; k < n; ++k) r[k] = (X[k] - centroid).norm();
  s.lobes = prominent_maxima(r, opt.lobe_prominence * *std::max_element(r.begin(), r.end()));

  // two-ply runs: the nearest non-local point p(i) of each point, closer than d_c, moving the
  // other way along the rod at about the same pace (an antiparallel ply), over ≥ l_min
  std::vector<int> partner(n, -1);
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (cyclic_distance(i, j, n) < m_min) continue;
      const double d = (X[i] - X[j]).norm();
      if (d < dist[i]) {
        dist[i] = d;
        partner[i] = j;
      }
    }
  std::vector<char> close(n), linked(n);
  for (int i = 0; i < n; ++i) close[i] = partner[i] >= 0 && dist[i] <= dc;
  for (int i = 0; i < n; ++i) {
    const int k = (i + 1) % n;
    const int step = close[i] && close[k] ? wrap(partner[k] - partner[i], n) : 99;
    linked[i] = step >= -3 && step <= 1;  // i and i+1 are on one antiparallel ply
  }
  std::vector<char> ply(n, 0);
  int start = 0;
  while (start < n && linked[start]) ++start;
  if (start == n) start = 0;  // every link holds: one run around the ring
  for (int a = 1; a <= n;) {
    const int i0 = (start + a) % n;
    if (!close[i0]) {
      ++a;
      continue;
    }
    int len = 0, moved = 0;  // run i0 … i0+len; partner moved by `moved`
    while (len < n - 1 && linked[(i0 + len) % n]) {
      moved += wrap(partner[(i0 + len + 1) % n] - partner[(i0 + len) % n], n);
      ++len;
    }
    const double pace = len > 0 ? -double(moved) / len : 0.0;
    if (len * h >= l_min && pace >= 0.5 && pace <= 2.0) {
      ++s.interwound_runs;
      for (int q = 0; q <= len; ++q) ply[(i0 + q) % n] = 1;
      const int p_end = partner[(i0 + len) % n], p_begin = partner[i0];
      for (int q = 0, m = wrap(p_begin - p_end, n); q <= m; ++q) ply[(p_end + q) % n] = 1;
    }
    a += len + 1;
  }
  const int in_ply = int(std::count(ply.begin(), ply.end(), 1));
  s.interwound_length_A = 0.5 * in_ply * h;

  // terminal loops of a two-ply shape: arcs outside the plies, at least d_c long
  int arcs = 0;
  if (in_ply > 0 && in_ply < n) {
    int first = 0;
    while (!ply[first]) ++first;
    for (int a = 1, len = 0; a <= n; ++a) {
      const int k = (first + a) % n;
      if (!ply[k]) {
        ++len;
      } else {
        if (len * h >= dc) ++arcs;
        len = 0;
      }
    }
  }

  s.contact_clusters = int(contact_clusters(X, dc, s_min).size());

  // the class (docs/analysis.md "Shapes")
  if (s.crossings_mode == 0) {
    s.cls = ShapeClass::circle;
    s.loops = 1;
  } else if (s.crossings_mode >= 2 && s.interwound_length_A >= l_min) {
    s.cls = ShapeClass::plectonemic;
    s.loops = arcs;
  } else if (s.lobes >= 3) {
    s.cls = ShapeClass::toroidal;
    s.loops = s.lobes;
  } else if (s.crossings_mode <= 2) {
    s.cls = ShapeClass::figure8;
    s.loops = 2;
  } else {
    s.cls = ShapeClass::other;
    s.loops = s.lobes;
  }
  return s;
}

}  // namespace ibrod::diagnostics
