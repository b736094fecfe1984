// Ray casting of the rod as a chain of capsules (render.hpp).
#include "render/render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "render/text.hpp"

namespace ibrod::render {

namespace {

struct Hit {
  double t;  ///< distance along the ray
  double h;  ///< position of the nearest axis point along the segment, in [0, 1]
};

/// Nearest intersection (t ≥ 0) of the ray ro + t rd (|rd| = 1) with the capsule of radius r about
/// a → b, or t < 0 for a miss. Cylinder by the quadratic in t restricted to the segment's slab,
/// then the sphere cap on the side the cylinder hit fell (I. Quilez's capsule intersection).
Hit ray_capsule(const Vec3& ro, const Vec3& rd, const Vec3& a, const Vec3& b, double r) {
  const Vec3 ba = b - a, oa = ro - a;
  const double baba = ba.dot(ba), bard = ba.dot(rd), baoa = ba.dot(oa), rdoa = rd.dot(oa),
               oaoa = oa.dot(oa);
  const double qa = baba - bard * bard, qb = baba * rdoa - baoa * bard,
               qc = baba * oaoa - baoa * baoa - r * r * baba;
  double h = qb * qb - qa * qc;
  if (h < 0) return {-1, 0};
  double t = qa > 0 ? (-qb - std::sqrt(h)) / qa : -1;  // qa = 0: the ray runs along the axis
  const double y = baoa + t * bard;
  if (qa > 0 && y > 0 && y < baba) return {t, y / baba};
  // sphere cap at a (y ≤ 0) or at b
  const Vec3 oc = (y <= 0) ? oa : Vec3(ro - b);
  // the sphere's quadratic t² + 2 half_b t + c0 = 0 (|rd| = 1)
  const double half_b = rd.dot(oc), c0 = oc.dot(oc) - r * r;
  h = half_b * half_b - c0;
  if (h <= 0) return {-1, 0};
  return {-half_b - std::sqrt(h), y <= 0 ? 0.0 : 1.0};
}

std::uint8_t to_byte(double v) { return std::uint8_t(std::clamp(std::lround(v), 0L, 255L)); }

// A colour map of t in [0, 1]: blue → cyan → green → yellow → red (piecewise linear).
Rgb colour_map(double t) {
  static const double stops[5][3] = {
      {40, 70, 200}, {30, 170, 210}, {60, 180, 80}, {235, 200, 40}, {210, 50, 40}};
  t = std::clamp(t, 0.0, 1.0) * 4;
  const int i = std::min(3, int(t));
  const double f = t - i;
  return {to_byte((1 - f) * stops[i][0] + f * stops[i + 1][0]),
          to_byte((1 - f) * stops[i][1] + f * stops[i + 1][1]),
          to_byte((1 - f) * stops[i][2] + f * stops[i + 1][2])};
}

}  // namespace

std::vector<double> twist_density(std::span<const Vec3> X, std::span<const Vec3> d1) {
  const std::size_t n = X.size();
  if (n < 2 || d1.size() != n)
    throw std::invalid_argument("twist_density: needs at least 2 points and one director each");
  // vertex tangents (central differences) and D¹ made ⟂ to them
  std::vector<Vec3> t(n), d(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 c = X[(k + 1) % n] - X[(k + n - 1) % n];
    t[k] = c.norm() > 0 ? Vec3(c.normalized()) : Vec3(0, 0, 1);
    d[k] = d1[k] - d1[k].dot(t[k]) * t[k];
  }
  std::vector<double> tw(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t m = (k + 1) % n;
    const double len = (X[m] - X[k]).norm();
    const double c = t[k].dot(t[m]);
    if (!(len > 0) || !(c > -0.99)) continue;
    // D¹_k parallel-transported to t_{k+1} (the smallest rotation taking t_k to t_{k+1}), then
    // the signed angle to D¹_{k+1} about t_{k+1}
    const Vec3 w = t[k].cross(t[m]);
    const Vec3 p = c * d[k] + w.cross(d[k]) + w * (w.dot(d[k]) / (1 + c));
    tw[k] = std::atan2(p.cross(d[m]).dot(t[m]), p.dot(d[m])) / len;
  }
  return tw;
}

std::vector<std::string> standard_view_names() {
  return {"top", "bottom", "side", "front", "oblique"};
}

View standard_view(const std::string& name) {
  if (name == "top") return {name, {0, 0, -1}, {0, 1, 0}};
  if (name == "bottom") return {name, {0, 0, 1}, {0, 1, 0}};
  if (name == "side") return {name, {0, 1, 0}, {0, 0, 1}};
  if (name == "front") return {name, {-1, 0, 0}, {0, 0, 1}};
  if (name == "oblique") return {name, -Vec3(0.55, -0.8, 0.75).normalized(), {0, 0, 1}};
  std::string all;
  for (const auto& n : standard_view_names()) all += (all.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown view '" + name + "' (one of: " + all + ")");
}

Image render_rod(std::span<const Vec3> X, std::span<const Vec3> d1, double diameter,
                 const View& view, int width, int height, const Style& style,
                 std::span<const Vec3> frame) {
  const rod::RodRange ring{0, int(X.size()), true};
  return render_rods(X, d1, {&ring, 1}, diameter, view, width, height, style, frame);
}

Image render_rods(std::span<const Vec3> X, std::span<const Vec3> d1,
                  std::span<const rod::RodRange> rods, double diameter, const View& view, int width,
                  int height, const Style& style, std::span<const Vec3> frame) {
  const std::size_t n = X.size();
  if (n < 2) throw std::invalid_argument("render_rod: needs at least 2 points");
  if (d1.size() != n)
    throw std::invalid_argument("render_rod: " + std::to_string(d1.size()) + " directors for " +
                                std::to_string(n) + " points");
  if (!(diameter > 0)) throw std::invalid_argument("render_rod: diameter must be positive");
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("render_rod: image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is not positive");
  const int S = std::max(1, style.supersample);
  const int W = width * S, H = height * S;

  // camera frame: forward f, right r = f × up, true up u = r × f
  const Vec3 f = view.forward.normalized();
  const Vec3 right = f.cross(view.up);
  if (!(right.norm() > 1e-9 * view.up.norm()))
    throw std::invalid_argument("render_rod: view '" + view.name + "': up is parallel to forward");
  const Vec3 r = right.normalized();
  const Vec3 u = r.cross(f);
  const double R = 0.5 * diameter;

  // centre and scale (tight framing): the box the tube covers on the image plane, centred, fills
  // the image less the margins along its limiting side
  const std::span<const Vec3> fr = frame.empty() ? X : frame;
  double lo_r = std::numeric_limits<double>::infinity(), hi_r = -lo_r, lo_u = lo_r, hi_u = -lo_r,
         lo_f = lo_r;
  for (const auto& x : fr) {
    lo_r = std::min(lo_r, x.dot(r)), hi_r = std::max(hi_r, x.dot(r));
    lo_u = std::min(lo_u, x.dot(u)), hi_u = std::max(hi_u, x.dot(u));
    lo_f = std::min(lo_f, x.dot(f));
  }
  const double margin_px = style.margin * std::min(W, H);
  // bands for the labels (top) and the scale bar (bottom), in final pixels, kept free of the rod
  const int fs = std::max(1, int(std::lround(std::min(width, height) / 400.0)));  // font scale
  const int line_h = (kGlyphH + 3) * fs, pad = 3 * fs;
  const int top_band = style.labels.empty() ? 0 : int(style.labels.size()) * line_h + pad;
  const int triad_len = 12 * fs;  // axis triad: arm length in final pixels
  const int bottom_band = std::max(style.scale_bar ? (kGlyphH + 3) * fs + pad : 0,
                                   style.axis_triad ? 2 * triad_len + kGlyphH * fs + pad : 0);
  const double avail_h = H - 2 * margin_px - double(S) * (top_band + bottom_band);
  if (!(avail_h > 0))
    throw std::invalid_argument("render_rod: image height " + std::to_string(height) +
                                " leaves no room for the rod beside its labels");
  const double scale =  // pixels (supersampled) per length unit
      std::min((W - 2 * margin_px) / (hi_r - lo_r + 2 * R), avail_h / (hi_u - lo_u + 2 * R));
  // the box's centre goes to the centre of the free region
  const double ox = 0.5 * W, oy = 0.5 * (double(S) * top_band + H - double(S) * bottom_band);
  // the centre c: mid-box on the image plane; along f, in front of every point
  const Vec3 c = 0.5 * (lo_r + hi_r) * r + 0.5 * (lo_u + hi_u) * u + (lo_f - 2 * R) * f;
  const Vec3 eye = c;  // rays start on a plane in front of everything

  // light from the upper left, in front of the rod
  const Vec3 light = (-0.45 * r + 0.6 * u - 0.65 * f).normalized();

  std::vector<double> depth(std::size_t(W) * std::size_t(H),
                            std::numeric_limits<double>::infinity());
  std::vector<float> shade(depth.size(), 0.0f);
  std::vector<std::uint8_t> on_stripe(depth.size(), 0);
  std::vector<float> param(style.colouring == Colouring::stripe ? 0 : depth.size(), 0.0f);
  // arc length of the nearest hit's axis point from X_0, for the outlines
  std::vector<float> arc(depth.size(), 0.0f);
  // the rods laid end to end in X: each point's next and previous point along its rod (−1 past a
  // free end), its rod, and the rods' arc lengths
  {
    std::size_t total = 0;
    for (const rod::RodRange& g : rods) {
      if (g.offset != int(total))
        throw std::invalid_argument("render_rod: the rods are not laid end to end");
      total += std::size_t(g.n);
    }
    if (total != n) throw std::invalid_argument("render_rod: the rods' points are not X's");
  }
  std::vector<long> next(n, -1), prev(n, -1);
  std::vector<int> rod_of(n, 0);
  std::vector<double> rod_len;
  rod::for_each_rod(rods, [&](std::size_t r, const rod::RodRange& g) {
    const std::size_t off = std::size_t(g.offset);
    rod_len.push_back(0.0);
    for (int k = 0; k < g.n; ++k) {  // −1: past an open rod's end
      rod_of[off + std::size_t(k)] = int(r);
      if (const int a = rod::after(g, k); a >= 0) next[off + std::size_t(k)] = long(off) + a;
      if (const int b = rod::before(g, k); b >= 0) prev[off + std::size_t(k)] = long(off) + b;
    }
  });
  // segments k → next[k]: n of a closed polygon, n − 1 of an open one, per rod
  std::vector<std::size_t> seg;
  for (std::size_t k = 0; k < n; ++k)
    if (next[k] >= 0) seg.push_back(k);
  // cum[k]: arc length from its rod's first point to point k
  std::vector<double> cum(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double len = next[k] >= 0 ? (X[std::size_t(next[k])] - X[k]).norm() : 0.0;
    rod_len[rod_of[k]] += len;
    if (next[k] > long(k)) cum[std::size_t(next[k])] = cum[k] + len;
  }
  double z_lo = std::numeric_limits<double>::infinity(), z_hi = -z_lo;
  // twist colouring: the twist density at each point (mean of its two segments), mapped from
  // the frame's lowest (0) to its highest (1); uniform twist: the middle of the map
  std::vector<double> tw_point;
  if (style.colouring == Colouring::twist) {
    tw_point.resize(n);
    std::size_t off = 0;
    for (const rod::RodRange& g : rods) {
      const std::size_t m = std::size_t(g.n);
      const auto tw = twist_density(X.subspan(off, m), d1.subspan(off, m));
      // the mean of the point's two segments: segment k starts at point k, the one before it
      // (from point b) ends there; an open rod's ends have one segment each
      for (int k = 0; k < g.n; ++k) {
        const int b = rod::before(g, k), a = rod::after(g, k);
        tw_point[off + std::size_t(k)] = b >= 0 && a >= 0
                                             ? 0.5 * (tw[std::size_t(b)] + tw[std::size_t(k)])
                                             : tw[std::size_t(b >= 0 ? b : k)];
      }
      off += m;
    }
    const auto [lo, hi] = std::minmax_element(tw_point.begin(), tw_point.end());
    const double t_lo = *lo, t_hi = *hi, t_span = t_hi - t_lo;
    const bool uniform = !(t_span > 1e-6 * std::max(std::abs(t_lo), std::abs(t_hi)));
    for (auto& t : tw_point) t = uniform ? 0.5 : (t - t_lo) / t_span;
  }
  for (const auto& x : X) z_lo = std::min(z_lo, x.z()), z_hi = std::max(z_hi, x.z());

  // vertex tangents (central differences; one-sided at free ends), blended along each segment
  // for smooth shading
  std::vector<Vec3> vtan(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& ahead = next[k] >= 0 ? X[std::size_t(next[k])] : X[k];
    const Vec3& behind = prev[k] >= 0 ? X[std::size_t(prev[k])] : X[k];
    const Vec3 d = ahead - behind;
    vtan[k] = d.norm() > 0 ? Vec3(d.normalized()) : Vec3(f);
  }
  std::vector<int> rod_hit(depth.size(), 0);  // the nearest hit's rod, for the outlines

  for (const std::size_t k : seg) {
    const std::size_t k1 = std::size_t(next[k]);
    const Vec3& a = X[k];
    const Vec3& b = X[k1];
    const Vec3 ab = b - a;
    const double len = ab.norm();
    const Vec3 tan = len > 0 ? Vec3(ab / len) : Vec3(f);
    // the segment's screen box, grown by the radius
    const double ax = (a - c).dot(r) * scale, ay = (a - c).dot(u) * scale;
    const double bx = (b - c).dot(r) * scale, by = (b - c).dot(u) * scale;
    const double pad_px = R * scale + 1;
    const int x0 = std::max(0, int(std::floor(ox + std::min(ax, bx) - pad_px)));
    const int x1 = std::min(W - 1, int(std::ceil(ox + std::max(ax, bx) + pad_px)));
    const int y0 = std::max(0, int(std::floor(oy - std::max(ay, by) - pad_px)));
    const int y1 = std::min(H - 1, int(std::ceil(oy - std::min(ay, by) + pad_px)));
    for (int py = y0; py <= y1; ++py) {
      for (int px = x0; px <= x1; ++px) {
        const double sx = (px + 0.5 - ox) / scale, sy = (oy - (py + 0.5)) / scale;
        const Vec3 ro = eye + sx * r + sy * u;
        const Hit hit = ray_capsule(ro, f, a, b, R);
        const std::size_t idx = std::size_t(py) * std::size_t(W) + std::size_t(px);
        if (hit.t < 0 || hit.t >= depth[idx]) continue;
        depth[idx] = hit.t;
        const Vec3 p = ro + hit.t * f;
        const Vec3 axis = a + hit.h * ab;
        const Vec3 nrm = (p - axis).normalized();
        // D¹ along the segment, ⟂ to its tangent
        Vec3 d = (1 - hit.h) * d1[k] + hit.h * d1[k1];
        d -= d.dot(tan) * tan;
        // compare directions ⟂ to the axis, with the tangent blended between the vertices (on
        // a cap the normal also leans along the axis; a polygonal tube would look faceted)
        Vec3 tb = (1 - hit.h) * vtan[k] + hit.h * vtan[k1];
        tb = tb.norm() > 1e-12 ? Vec3(tb.normalized()) : tan;
        const Vec3 np = nrm - nrm.dot(tb) * tb;
        const double dn = d.norm() * np.norm();
        on_stripe[idx] = dn > 0 && np.dot(d) / dn > style.stripe_cos;
        // shade with the same ⟂ normal (Phong-like smoothing across the joints)
        const Vec3 ns = np.norm() > 1e-12 ? Vec3(np.normalized()) : nrm;
        shade[idx] = float(style.ambient + (1 - style.ambient) * std::max(0.0, ns.dot(light)));
        arc[idx] = float(cum[k] + hit.h * len);
        rod_hit[idx] = rod_of[k];
        if (style.colouring == Colouring::along)
          param[idx] = float((double(k) + hit.h) / double(n));
        else if (style.colouring == Colouring::height)
          param[idx] = z_hi > z_lo ? float((axis.z() - z_lo) / (z_hi - z_lo)) : 0.5f;
        else if (style.colouring == Colouring::twist)
          param[idx] = float((1 - hit.h) * tw_point[k] + hit.h * tw_point[k1]);
      }
    }
  }

  // outlines: darken the nearer side of every occlusion boundary (a neighbour within about one
  // pixel is background, or lies behind by more than the radius on a part of the rod more than
  // style.outline_arc diameters away along it), so crossings read as such; where the tube turns
  // toward the viewer in front of its own continuation there is no line across it, which would
  // look like the cap of a free end
  const double arc_gap = style.outline_arc * diameter;
  // two hits far apart along the rod: on different rods, or on one rod more than arc_gap apart
  const auto far_along = [&](std::size_t i1, std::size_t i2) {
    if (rod_hit[i1] != rod_hit[i2]) return true;
    const std::size_t r = std::size_t(rod_hit[i1]);
    return rod::arc_distance(rods[r], double(arc[i1]), double(arc[i2]), rod_len[r]) > arc_gap;
  };
  if (style.outline_darken < 1) {
    const int reach = S;
    std::vector<std::uint8_t> edge(depth.size(), 0);
    for (int py = 0; py < H; ++py)
      for (int px = 0; px < W; ++px) {
        const std::size_t idx = std::size_t(py) * std::size_t(W) + std::size_t(px);
        if (!std::isfinite(depth[idx])) continue;
        for (int d = 1; d <= reach && !edge[idx]; ++d) {
          const int nx[4] = {px - d, px + d, px, px}, ny[4] = {py, py, py - d, py + d};
          for (int q = 0; q < 4; ++q) {
            if (nx[q] < 0 || ny[q] < 0 || nx[q] >= W || ny[q] >= H) continue;
            const std::size_t nq = std::size_t(ny[q]) * std::size_t(W) + std::size_t(nx[q]);
            if (!std::isfinite(depth[nq]) || (depth[nq] > depth[idx] + R && far_along(nq, idx)))
              edge[idx] = 1;
          }
        }
      }
    for (std::size_t i = 0; i < edge.size(); ++i)
      if (edge[i]) shade[i] *= float(style.outline_darken);
  }

  // depth cue: the nearest surface as shaded, the farthest blended depth_cue toward the background
  double d_lo = std::numeric_limits<double>::infinity(), d_hi = -d_lo;
  for (const double d : depth)
    if (std::isfinite(d)) d_lo = std::min(d_lo, d), d_hi = std::max(d_hi, d);
  const double d_span = d_hi > d_lo ? d_hi - d_lo : 1;

  // shade and average S×S blocks
  Image img(width, height, style.background);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double acc[3] = {0, 0, 0};
      for (int j = 0; j < S; ++j) {
        for (int i = 0; i < S; ++i) {
          const std::size_t idx = std::size_t(y * S + j) * std::size_t(W) + std::size_t(x * S + i);
          Rgb col = style.background;
          double s = 1;
          double fog = 0;
          if (std::isfinite(depth[idx])) {
            if (style.colouring == Colouring::stripe) {
              col = on_stripe[idx] ? style.stripe : style.tube;
            } else {
              col = colour_map(param[idx]);
              if (on_stripe[idx])
                col = {to_byte(0.55 * col.r), to_byte(0.55 * col.g), to_byte(0.55 * col.b)};
            }
            s = shade[idx];
            fog = style.depth_cue * (depth[idx] - d_lo) / d_span;
          }
          const Rgb& bg = style.background;
          acc[0] += (1 - fog) * s * col.r + fog * bg.r;
          acc[1] += (1 - fog) * s * col.g + fog * bg.g;
          acc[2] += (1 - fog) * s * col.b + fog * bg.b;
        }
      }
      const double w = 1.0 / double(S * S);
      img.set(x, y, {to_byte(w * acc[0]), to_byte(w * acc[1]), to_byte(w * acc[2])});
    }
  }

  // labels at the top left, the scale bar at the bottom left (final pixels)
  const int mx = int(std::lround(margin_px / S));
  for (std::size_t i = 0; i < style.labels.size(); ++i)
    draw_text(img, mx, mx + int(i) * line_h, style.labels[i], fs, style.ink);
  if (style.scale_bar) {
    const double px_per_unit = scale / S;
    double len = style.scale_bar_length;
    if (!(len > 0)) {  // 1, 2 or 5 × 10^k, the largest not above a quarter of the width
      const double most = 0.25 * width / px_per_unit;
      const double p10 = std::pow(10.0, std::floor(std::log10(most)));
      len = most >= 5 * p10 ? 5 * p10 : most >= 2 * p10 ? 2 * p10 : p10;
    }
    const int bar = int(std::lround(len * px_per_unit)), thick = 2 * fs;
    const int yb = height - mx - thick;
    for (int y = std::max(0, yb); y < yb + thick && y < height; ++y)
      for (int x = mx; x < mx + bar && x < width; ++x) img.set(x, y, style.ink);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g Å", len);
    draw_text(img, mx + bar + 3 * fs, yb + thick - kGlyphH * fs, buf, fs, style.ink);
  }
  if (style.axis_triad) {
    // the lab axes x, y, z projected on the picture, from a centre at the bottom right; an axis
    // along the line of sight has a short arm (its letter sits at the centre)
    const int cx = width - mx - triad_len - kGlyphW * fs, cy = height - mx - triad_len;
    const Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const char* names[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      const double dx = axes[a].dot(r) * triad_len, dy = -axes[a].dot(u) * triad_len;
      const int steps = std::max(1, int(std::ceil(std::max(std::abs(dx), std::abs(dy)))));
      for (int i = 0; i <= steps; ++i) {
        const int px = cx + int(std::lround(dx * i / steps)),
                  py = cy + int(std::lround(dy * i / steps));
        for (int j = 0; j < fs; ++j)
          for (int k = 0; k < fs; ++k)
            if (px + j >= 0 && py + k >= 0 && px + j < width && py + k < height)
              img.set(px + j, py + k, style.ink);
      }
      const double len = std::hypot(dx, dy);
      const double lx = len > 0 ? dx / len : 0, ly = len > 0 ? dy / len : 0;
      draw_text(img, cx + int(std::lround(dx + lx * 5 * fs)) - (kGlyphW * fs) / 2,
                cy + int(std::lround(dy + ly * 6 * fs)) - (kGlyphH * fs) / 2, names[a], fs,
                style.ink);
    }
  }
  return img;
}

}  // namespace ibrod::render
