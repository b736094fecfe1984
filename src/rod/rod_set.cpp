#include "rod/rod_set.hpp"

#include <cmath>

namespace ibrod::rod {

std::vector<RodRange> ranges_of(std::span<const RodParams> rods) {
  std::vector<RodRange> r;
  r.reserve(rods.size());
  int offset = 0;
  for (const RodParams& p : rods) {
    r.push_back({offset, p.n, p.closed, p.ds});
    offset += p.n;
  }
  return r;
}

int total_points(std::span<const RodRange> rods) {
  int n = 0;
  for (const RodRange& r : rods) n += r.n;
  return n;
}

int total_points(std::span<const RodParams> rods) {
  int n = 0;
  for (const RodParams& r : rods) n += r.n;
  return n;
}

bool names_rods(std::span<const RodRange> rods) { return rods.size() > 1; }
bool names_rods(std::span<const RodParams> rods) { return rods.size() > 1; }

std::string message_prefix(std::span<const RodRange> rods, std::size_t r) {
  return names_rods(rods) ? "rod " + std::to_string(r) + ": " : std::string();
}
std::string message_prefix(std::span<const RodParams> rods, std::size_t r) {
  return names_rods(rods) ? "rod " + std::to_string(r) + ": " : std::string();
}

std::string describe(std::span<const RodRange> rods) {
  return std::to_string(total_points(rods)) + " rod points (rods: " + std::to_string(rods.size()) +
         ")";
}

std::string count_label(std::span<const RodRange> rods) {
  return std::to_string(rods.size()) + " rods";
}

bool one_ring(std::span<const RodRange> rods) { return rods.size() == 1 && rods[0].closed; }

void extract(const RodState& all, const RodRange& r, RodState& out) {
  if (out.size() != r.n) {
    out.X.resize(r.n);
    out.D.resize(r.n);
  }
  for (int k = 0; k < r.n; ++k) {
    out.X[k] = all.X[r.offset + k];
    out.D[k] = all.D[r.offset + k];
  }
}

void insert(RodState& all, const RodRange& r, const RodState& one) {
  for (int k = 0; k < r.n; ++k) {
    all.X[r.offset + k] = one.X[k];
    all.D[r.offset + k] = one.D[k];
  }
}

void append(RodState& all, const RodState& one) {
  all.X.insert(all.X.end(), one.X.begin(), one.X.end());
  all.D.insert(all.D.end(), one.D.begin(), one.D.end());
}

Mat3 rotation_xyz_deg(const Vec3& a) {
  const double deg = std::acos(-1.0) / 180.0;
  const Mat3 Rx = Eigen::AngleAxisd(a[0] * deg, Vec3::UnitX()).toRotationMatrix();
  const Mat3 Ry = Eigen::AngleAxisd(a[1] * deg, Vec3::UnitY()).toRotationMatrix();
  const Mat3 Rz = Eigen::AngleAxisd(a[2] * deg, Vec3::UnitZ()).toRotationMatrix();
  return Rz * Ry * Rx;
}

void place(RodState& s, const Mat3& R, const Vec3& shift) {
  const int n = s.size();
  if (n == 0) return;
  Vec3 c = Vec3::Zero();
  for (const Vec3& x : s.X) c += x;
  c /= double(n);
  for (int k = 0; k < n; ++k) {
    s.X[k] = c + shift + R * (s.X[k] - c);
    s.D[k] = R * s.D[k];
  }
}

}  // namespace ibrod::rod
