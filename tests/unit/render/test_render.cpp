// Rendering of a known circle: the PNG has the requested size and reads back unchanged; the
// background shows where the rod is absent (the ring's centre, the corners) and the rod where it
// is (on the ring); views differ; the stripe follows D¹; a twisted ribbon shows a stripe that
// winds around the tube.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "render/image.hpp"
#include "render/render.hpp"
#include "render/text.hpp"

namespace ibrod::render {
namespace {

constexpr double kPi = std::numbers::pi;

/// A circle of radius r0 about c in the z = 0 plane, n points, and a D¹ that turns `turns`
/// times about the tangent, starting at angle phi0 from +z.
struct Ring {
  std::vector<Vec3> X, d1;
  Ring(int n, double r0, int turns = 0, double phi0 = 0, Vec3 c = Vec3(10, -5, 3)) {
    for (int k = 0; k < n; ++k) {
      const double s = 2 * kPi * k / n;
      const Vec3 radial(std::cos(s), std::sin(s), 0), z(0, 0, 1);
      X.push_back(c + r0 * radial);
      const double phi = phi0 + turns * s;
      d1.push_back(std::cos(phi) * z + std::sin(phi) * radial);
    }
  }
};

bool is_background(Rgb p, Rgb bg = Style{}.background) { return p == bg; }
bool is_tube(Rgb p) { return p.b > p.r + 20; }    // blue body, any shade
bool is_stripe(Rgb p) { return p.r > p.b + 20; }  // orange stripe, any shade

/// Pixel of the point x of the top view, for a ring centred like Ring's (the centroid is c).
struct TopViewMap {
  double scale;  // px per Å
  int w, h;
  TopViewMap(double r0, double D, int w_, int h_) : w(w_), h(h_) {
    scale = 0.5 * std::min(w, h) * (1 - 2 * Style{}.margin) / (r0 + D / 2);
  }
  int px(double dx) const { return int(std::floor(0.5 * w + dx * scale)); }
  int py(double dy) const { return int(std::floor(0.5 * h - dy * scale)); }
};

TEST(Png, WritesTheRequestedSizeAndReadsBackTheSamePixels) {
  const Ring ring(200, 100.0);
  const Image img = render_rod(ring.X, ring.d1, 20.0, standard_view("oblique"), 320, 240);
  const auto path = std::filesystem::temp_directory_path() /
                    ("ibrod_render_png_" + std::to_string(::getpid()) + ".png");
  write_png(path.string(), img);
  const Image back = read_png(path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(back.width, 320);
  EXPECT_EQ(back.height, 240);
  EXPECT_EQ(back.rgb, img.rgb);
  EXPECT_THROW(read_png("/nonexistent/ibrod.png"), std::runtime_error);
}

TEST(Render, BackgroundInsideTheRingRodOnIt) {
  const double r0 = 100, D = 20;
  const Ring ring(300, r0);  // D¹ = +z: the stripe faces the top-view camera
  const int w = 200, h = 200;
  const Image img = render_rod(ring.X, ring.d1, D, standard_view("top"), w, h);
  const TopViewMap m(r0, D, w, h);
  EXPECT_TRUE(is_background(img.at(w / 2, h / 2)));  // the centre of the ring
  EXPECT_TRUE(is_background(img.at(0, 0)));
  EXPECT_TRUE(is_background(img.at(w - 1, h - 1)));
  // a radius 0.8 r0 (inside the hole: the tube spans r0 ± 10 Å) and 1.15 r0 (outside)
  EXPECT_TRUE(is_background(img.at(m.px(0.8 * r0), h / 2)));
  EXPECT_TRUE(is_background(img.at(w / 2, m.py(1.15 * r0))));
  // on the ring at eight angles: rod, and the centreline shows the stripe (D¹ = +z faces us)
  for (int q = 0; q < 8; ++q) {
    const double a = 2 * kPi * (q + 0.5) / 8;
    const Rgb p = img.at(m.px(r0 * std::cos(a)), m.py(r0 * std::sin(a)));
    EXPECT_FALSE(is_background(p)) << "angle " << a;
    EXPECT_TRUE(is_stripe(p)) << "angle " << a << ": " << int(p.r) << "," << int(p.g) << ","
                              << int(p.b);
  }
  // near the inner and outer rims the normal is ⟂ to D¹: tube colour
  const Rgb rim = img.at(m.px(r0 + 0.8 * D / 2), h / 2);
  EXPECT_TRUE(is_tube(rim)) << int(rim.r) << "," << int(rim.g) << "," << int(rim.b);
}

TEST(Render, StripeFollowsD1) {
  const double r0 = 100, D = 20;
  const int w = 200, h = 200;
  const TopViewMap m(r0, D, w, h);
  const Ring up(300, r0, 0, 0), down(300, r0, 0, kPi);  // D¹ = +z, −z
  const Image a = render_rod(up.X, up.d1, D, standard_view("top"), w, h);
  const Image b = render_rod(down.X, down.d1, D, standard_view("top"), w, h);
  int stripe_a = 0, stripe_b = 0, tube_b = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      stripe_a += is_stripe(a.at(x, y));
      stripe_b += is_stripe(b.at(x, y));
      tube_b += is_tube(b.at(x, y));
    }
  EXPECT_GT(stripe_a, 500);  // a band along the whole ring
  EXPECT_EQ(stripe_b, 0);    // the stripe is underneath, out of sight
  EXPECT_GT(tube_b, 2000);
  EXPECT_TRUE(is_tube(b.at(m.px(r0), h / 2)));
}

TEST(Render, ViewsDiffer) {
  const double r0 = 100, D = 20;
  const Ring ring(300, r0, 3);
  const int w = 160, h = 160;
  const Image top = render_rod(ring.X, ring.d1, D, standard_view("top"), w, h);
  const Image side = render_rod(ring.X, ring.d1, D, standard_view("side"), w, h);
  const Image obl = render_rod(ring.X, ring.d1, D, standard_view("oblique"), w, h);
  auto differing = [&](const Image& p, const Image& q) {
    int k = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) k += !(p.at(x, y) == q.at(x, y));
    return k;
  };
  EXPECT_GT(differing(top, side), w * h / 20);
  EXPECT_GT(differing(top, obl), w * h / 20);
  EXPECT_GT(differing(side, obl), w * h / 20);
  // edge-on, the circle is a horizontal band through the middle: the centre is rod, the top
  // row of the image is not
  EXPECT_FALSE(is_background(side.at(w / 2, h / 2)));
  EXPECT_TRUE(is_background(side.at(w / 2, h / 4)));
  EXPECT_TRUE(is_background(top.at(w / 2, h / 2)));
}

TEST(Render, TwistWindsTheStripeAroundTheTube) {
  // with ΔLk = 4 turns of D¹ the top view's centreline shows the stripe where D¹ faces +z:
  // alternating stripe and tube along the ring, 4 stripe runs
  const double r0 = 100, D = 20;
  const Ring ring(600, r0, 4);
  const int w = 240, h = 240;
  const Image img = render_rod(ring.X, ring.d1, D, standard_view("top"), w, h);
  const TopViewMap m(r0, D, w, h);
  // count tube → stripe transitions; pixels at a stripe's edge (mixed colours) keep the state
  int runs = 0;
  bool prev = false;
  const int samples = 720;
  for (int q = 0; q <= samples; ++q) {
    const double a = 2 * kPi * q / samples;
    const Rgb p = img.at(m.px(r0 * std::cos(a)), m.py(r0 * std::sin(a)));
    const bool clear_stripe = p.r > p.b + 60, clear_tube = p.b > p.r + 60;
    if (clear_stripe && !prev) ++runs;
    if (clear_stripe || clear_tube) prev = clear_stripe;
  }
  // 4 turns: 4 runs, the one through angle 0 counted at both ends at most
  EXPECT_GE(runs, 4);
  EXPECT_LE(runs, 5);
}

/// The box of the pixels that are not background: {x0, y0, x1, y1} (inclusive).
std::array<int, 4> foreground_box(const Image& img) {
  std::array<int, 4> b{img.width, img.height, -1, -1};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (!is_background(img.at(x, y)))
        b = {std::min(b[0], x), std::min(b[1], y), std::max(b[2], x), std::max(b[3], y)};
  return b;
}

TEST(Render, TightFramingFillsTheImageAlongTheLimitingSideAndCentresTheOther) {
  // an elongated closed loop (semi-axes 300 and 40 Å, not centred at the origin), top view,
  // 300×200 px: the long side fills the width less the margins, the short one is centred
  std::vector<Vec3> X, d1;
  const int n = 400;
  for (int k = 0; k < n; ++k) {
    const double s = 2 * kPi * k / n;
    X.emplace_back(50 + 300 * std::cos(s), -20 + 40 * std::sin(s), 7);
    d1.emplace_back(0, 0, 1);
  }
  const int w = 300, h = 200;
  const Image img = render_rod(X, d1, 20.0, standard_view("top"), w, h);
  const auto b = foreground_box(img);
  const int margin = int(std::lround(Style{}.margin * std::min(w, h)));  // 8 px
  EXPECT_NEAR(b[0], margin, 2);
  EXPECT_NEAR(b[2], w - 1 - margin, 2);
  const int top = b[1], bottom = h - 1 - b[3];
  EXPECT_NEAR(top, bottom, 2);
  // height of the loop's picture: (2·40 + 20) Å at the scale (w − 2 margin) / (2·300 + 20) px/Å
  EXPECT_NEAR(b[3] - b[1] + 1, 100.0 * (w - 2 * margin) / 620.0, 3);
}

TEST(Render, AGivenFrameSetsScaleAndCentreForEveryPicture) {
  // a movie: a ring of 50 Å framed by the points of a ring of 100 Å about the same centre is
  // drawn at the larger ring's scale (half as large), centred
  const Ring small(200, 50.0), large(200, 100.0);
  const int w = 200, h = 200;
  const Image img =
      render_rod(small.X, small.d1, 20.0, standard_view("top"), w, h, Style{}, large.X);
  const auto b = foreground_box(img);
  const double scale = (w - 2 * Style{}.margin * w) / (2 * 100.0 + 20);
  EXPECT_NEAR(b[2] - b[0] + 1, (2 * 50.0 + 20) * scale, 3);
  EXPECT_NEAR(b[0], w - 1 - b[2], 2);
  EXPECT_NEAR(b[1], h - 1 - b[3], 2);
}

TEST(Text, GlyphsInkOnlyTheirCellsAndWidthsAddUp) {
  EXPECT_EQ(text_width("", 2), 0);
  EXPECT_EQ(text_width("8", 1), kGlyphW);
  EXPECT_EQ(text_width("ΔLk = 6 µs Å", 3), (12 * kGlyphAdvance - 1) * 3);  // UTF-8: 12 glyphs
  Image img(40, 20, {255, 255, 255});
  draw_text(img, 3, 4, "18", 2, {0, 0, 0});
  int inked = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (img.at(x, y) == Rgb{0, 0, 0}) {
        ++inked;
        EXPECT_GE(x, 3);
        EXPECT_LT(x, 3 + text_width("18", 2));
        EXPECT_GE(y, 4);
        EXPECT_LT(y, 4 + kGlyphH * 2);
      }
  EXPECT_GT(inked, 20 * 4);  // "1" and "8" have 10 + 17 font pixels, each 2×2
  // an unknown character is a box, not nothing
  Image unk(10, 10, {255, 255, 255});
  draw_text(unk, 0, 0, "?", 1, {0, 0, 0});
  EXPECT_EQ(unk.at(0, 0), (Rgb{0, 0, 0}));
}

bool is_ink(Rgb p) { return p == Style{}.ink; }
bool is_colour(Rgb p) { return std::max({p.r, p.g, p.b}) - std::min({p.r, p.g, p.b}) > 30; }

TEST(Render, LabelsAndScaleBarStayOutOfTheRodAndTheBarHasItsStatedLength) {
  // top view of a ring of 100 Å (tube 20 Å): its picture is 220 Å wide, so a 100 Å bar is
  // 100/220 of the ring's width in pixels
  const Ring ring(300, 100.0);
  Style st;
  st.labels = {"t = 1.0000 µs", "Wr = 0.000", "ΔLk = 4   Cs = 0.1 M"};
  st.scale_bar = true;
  st.scale_bar_length = 100;
  const int w = 400, h = 400;
  const Image img = render_rod(ring.X, ring.d1, 20.0, standard_view("top"), w, h, st);
  int ring_x0 = w, ring_x1 = -1, ring_y0 = h, ring_y1 = -1, ink_top = -1, ink_bottom = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (is_colour(img.at(x, y)))
        ring_x0 = std::min(ring_x0, x), ring_x1 = std::max(ring_x1, x),
        ring_y0 = std::min(ring_y0, y), ring_y1 = std::max(ring_y1, y);
      if (is_ink(img.at(x, y)) && y < h / 2) ink_top = std::max(ink_top, y);
      if (is_ink(img.at(x, y)) && y >= h / 2) ink_bottom = std::min(ink_bottom, y);
    }
  ASSERT_GE(ink_top, 0) << "no labels";
  ASSERT_LT(ink_bottom, h) << "no scale bar";
  EXPECT_LT(ink_top, ring_y0) << "labels overlap the rod";
  EXPECT_GT(ink_bottom, ring_y1) << "scale bar overlaps the rod";
  // the bar: the longest run of ink in the bottom rows
  int bar = 0;
  for (int y = ink_bottom; y < h; ++y) {
    int run = 0;
    for (int x = 0; x < w; ++x) {
      run = is_ink(img.at(x, y)) ? run + 1 : 0;
      bar = std::max(bar, run);
    }
  }
  const double ring_px = ring_x1 - ring_x0 + 1;
  EXPECT_NEAR(bar, ring_px * 100.0 / 220.0, 2.0);
}

TEST(Render, AxisTriadShowsXRightAndYUpInTheTopViewBelowTheRod) {
  const Ring ring(300, 100.0);
  Style st;
  st.axis_triad = true;
  const int w = 400, h = 400;
  const Image img = render_rod(ring.X, ring.d1, 20.0, standard_view("top"), w, h, st);
  // longest horizontal and vertical runs of ink in the bottom right corner
  int hx0 = 0, hy = 0, hlen = 0, vx = 0, vy1 = 0, vlen = 0, ring_bottom = 0, ink_top = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0, run = 0; x < w; ++x) {
      if (is_colour(img.at(x, y))) ring_bottom = std::max(ring_bottom, y);
      run = is_ink(img.at(x, y)) && x > w / 2 ? run + 1 : 0;
      if (run > 0) ink_top = std::min(ink_top, y);
      if (run > hlen) hlen = run, hx0 = x - run + 1, hy = y;
    }
  for (int x = w / 2; x < w; ++x)
    for (int y = 0, run = 0; y < h; ++y) {
      run = is_ink(img.at(x, y)) ? run + 1 : 0;
      if (run > vlen) vlen = run, vx = x, vy1 = y;
    }
  EXPECT_NEAR(hlen, 13, 1);  // the x arm: 12 px plus its start pixel, pointing right
  EXPECT_NEAR(vlen, 13, 1);  // the y arm, pointing up
  EXPECT_NEAR(hx0, vx, 1);   // both start at the centre (z points at the eye: no arm)
  EXPECT_NEAR(hy, vy1, 1);
  EXPECT_LT(ring_bottom, ink_top) << "the triad overlaps the rod";
}

TEST(Render, DepthCueLightensTheFarSideAndColourMapsFollowTheRod) {
  // a ring seen edge-on from the side: its near and far halves overlap on screen; seen from the
  // top with a tilt, the far side is lighter with the depth cue than without
  Ring ring(300, 100.0);
  for (auto& x : ring.X) x.z() += 0.5 * (x.y() + 5);  // tilted: +y is higher (nearer the eye)
  Style plain;
  plain.depth_cue = 0;
  Style cue;
  cue.depth_cue = 0.5;
  const int w = 200, h = 200;
  const Image a = render_rod(ring.X, ring.d1, 20.0, standard_view("top"), w, h, plain);
  const Image b = render_rod(ring.X, ring.d1, 20.0, standard_view("top"), w, h, cue);
  const auto lum = [](Rgb p) { return int(p.r) + p.g + p.b; };
  // the lowest (far) and highest (near) rows of the ring, at the centre column
  int y_near = -1, y_far = -1;
  for (int y = 0; y < h; ++y)
    if (!is_background(a.at(w / 2, y))) {
      if (y_near < 0) y_near = y + 3;
      y_far = y - 3;
    }
  ASSERT_GT(y_far, y_near);
  EXPECT_GT(lum(b.at(w / 2, y_far)), lum(a.at(w / 2, y_far)) + 30);     // far: lighter
  EXPECT_NEAR(lum(b.at(w / 2, y_near)), lum(a.at(w / 2, y_near)), 30);  // near: about the same
  // colour along the rod: the start (points just after 0, at +x, y > 0) is blue, the middle
  // (−x) green
  Style along;
  along.colouring = Colouring::along;
  along.depth_cue = 0;
  const Ring flat(300, 100.0, 0, kPi / 2);  // D¹ in the plane: no stripe seen from the top
  const Image c = render_rod(flat.X, flat.d1, 20.0, standard_view("top"), w, h, along);
  int x_start = -1, x_mid = -1;
  for (int x = w - 1; x >= 0 && x_start < 0; --x)
    if (!is_background(c.at(x, h / 2 - 4))) x_start = x - 3;
  for (int x = 0; x < w && x_mid < 0; ++x)
    if (!is_background(c.at(x, h / 2))) x_mid = x + 3;
  const Rgb start = c.at(x_start, h / 2 - 4), mid = c.at(x_mid, h / 2);  // y > 0: k small
  EXPECT_GT(start.b, start.r + 40);                                      // blue
  EXPECT_GT(mid.g, mid.r);                                               // green
  EXPECT_GT(mid.g, mid.b);
}

TEST(Render, ATubeTurningTowardTheViewerHasNoOutlineAcrossItLikeAFreeEnd) {
  // a 200 × 60 Å rectangle standing in the x–z plane (points 5 Å apart), seen from above with a
  // 15° tilt: its upper (near) edge hides most of the lower one, and at the corners the tube
  // turns away from the viewer behind its own near end. Inside the rod's silhouette the outline
  // may only mark the near edge passing over the far one (one horizontal line); a line across
  // the tube at a corner, where the near edge meets its own continuation, would draw the cap of
  // a free end.
  std::vector<Vec3> X, d1;
  const auto edge = [&](Vec3 a, Vec3 b) {
    const int m = int(std::lround((b - a).norm() / 5));
    for (int i = 0; i < m; ++i)
      X.push_back(a + (b - a) * (double(i) / m)), d1.emplace_back(0, 1, 0);
  };
  edge({-100, 0, 0}, {100, 0, 0});
  edge({100, 0, 0}, {100, 0, 60});
  edge({100, 0, 60}, {-100, 0, 60});
  edge({-100, 0, 60}, {-100, 0, 0});
  const double tilt = 15 * kPi / 180;
  const View view{"tilted", Vec3(0, std::sin(tilt), -std::cos(tilt)), Vec3(0, 1, 0)};
  Style plain, outlined;
  plain.outline_darken = 1;
  const int w = 400, h = 200;
  const Image a = render_rod(X, d1, 20.0, view, w, h, plain);
  const Image b = render_rod(X, d1, 20.0, view, w, h, outlined);
  const auto near_background = [&](int x, int y) {
    for (int j = -2; j <= 2; ++j)
      for (int i = -2; i <= 2; ++i)
        if (x + i >= 0 && y + j >= 0 && x + i < w && y + j < h && is_background(a.at(x + i, y + j)))
          return true;
    return false;
  };
  int silhouette = 0, inside = 0, y_lo = h, y_hi = -1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (!(a.at(x, y) == b.at(x, y))) {
        if (near_background(x, y)) {
          ++silhouette;
        } else {
          ++inside;
          y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
        }
      }
  EXPECT_GT(silhouette, 500);  // the silhouette is outlined
  EXPECT_GT(inside, 200);      // so is the near edge over the far one, across the picture
  EXPECT_LE(y_hi - y_lo, 1);   // and nothing else: no line across the tube at the corners
}

TEST(Render, TwistDensityOfATwistedRingAndTheTwistColouring) {
  // D¹ turns φ(s) = 3 s + 1.5 sin s about the tangent of a circle (s the angle, r0 = 100 Å):
  // twist density φ'(s)/r0 = (3 + 1.5 cos s)/r0, highest at s = 0 (+x), lowest at s = π (−x)
  const int n = 400;
  const double r0 = 100;
  std::vector<Vec3> X, d1;
  for (int k = 0; k < n; ++k) {
    const double s = 2 * kPi * k / n, phi = 3 * s + 1.5 * std::sin(s);
    const Vec3 radial(std::cos(s), std::sin(s), 0), z(0, 0, 1);
    X.push_back(r0 * radial);
    d1.push_back(std::cos(phi) * z + std::sin(phi) * radial);
  }
  const auto tw = twist_density(X, d1);
  ASSERT_EQ(tw.size(), std::size_t(n));
  double total = 0;
  for (int k = 0; k < n; ++k) {
    const double s = 2 * kPi * (k + 0.5) / n;  // the segment's middle
    // sign: D¹ turns from z toward the outward radial, i.e. right-handed about the tangent
    // (z × radial = tangent direction)
    EXPECT_NEAR(tw[k], (3 + 1.5 * std::cos(s)) / r0, 2e-3 / r0) << k;
    total += tw[k] * (X[(k + 1) % n] - X[k]).norm();
  }
  EXPECT_NEAR(total / (2 * kPi), 3.0, 1e-3);  // the twist of the ring, in turns
  // coloured: red (high twist) at +x, blue (low) at −x, from the top (away from the stripe)
  Style twist;
  twist.colouring = Colouring::twist;
  twist.depth_cue = 0;
  twist.stripe_cos = 2;  // no stripe: the body colour only
  const int w = 200, h = 200;
  const Image img = render_rod(X, d1, 20.0, standard_view("top"), w, h, twist);
  int x_hi = -1, x_lo = -1;
  for (int x = w - 1; x >= 0 && x_hi < 0; --x)
    if (!is_background(img.at(x, h / 2))) x_hi = x - 4;
  for (int x = 0; x < w && x_lo < 0; ++x)
    if (!is_background(img.at(x, h / 2))) x_lo = x + 4;
  const Rgb high = img.at(x_hi, h / 2), low = img.at(x_lo, h / 2);
  EXPECT_GT(high.r, high.b + 60);
  EXPECT_GT(low.b, low.r + 60);
  // a uniformly twisted ring: one colour all around (the middle of the map, green)
  const Ring uniform(300, 100.0, 4);
  const Image u = render_rod(uniform.X, uniform.d1, 20.0, standard_view("top"), w, h, twist);
  for (const int x : {x_hi, x_lo}) {
    const Rgb p = u.at(x, h / 2);
    EXPECT_GT(p.g, p.r) << x;
    EXPECT_GT(p.g, p.b) << x;
  }
}

TEST(Render, BadInputThrows) {
  const Ring ring(50, 10.0);
  const std::vector<Vec3> short_d1(ring.d1.begin(), ring.d1.begin() + 10);
  EXPECT_THROW(render_rod(ring.X, short_d1, 2.0, standard_view("top"), 10, 10),
               std::invalid_argument);
  EXPECT_THROW(render_rod(ring.X, ring.d1, 2.0, standard_view("top"), 0, 10),
               std::invalid_argument);
  EXPECT_THROW(standard_view("diagonal"), std::invalid_argument);
  View v{"bad", {0, 0, 1}, {0, 0, 2}};
  EXPECT_THROW(render_rod(ring.X, ring.d1, 2.0, v, 10, 10), std::invalid_argument);
}

}  // namespace
}  // namespace ibrod::render

namespace ibrod::render {
namespace {
TEST(Render, SeveralRodsAreSeparateTubes) {
  // two open rods along x, 200 Å long, at y = ±60 Å (style.rods): from the top, the strip
  // between them is background; as one rod of all points a segment would join the end of the
  // first to the start of the second, across that strip
  std::vector<Vec3> X, d1;
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 60; ++k) {
      X.emplace_back(-100.0 + 200.0 * k / 59, r == 0 ? -60.0 : 60.0, 0.0);
      d1.emplace_back(0, 0, 1);
    }
  const std::vector<rod::RodRange> two = {{0, 60, false}, {60, 60, false}};
  const std::vector<rod::RodRange> one = {{0, 120, false}};
  const int w = 200, h = 200;
  const Image a = render_rods(X, d1, two, 20.0, standard_view("top"), w, h);
  const Image b = render_rods(X, d1, one, 20.0, standard_view("top"), w, h);
  // the image's middle row: between the rods
  int joined = 0, apart = 0;
  for (int x = 0; x < w; ++x) {
    joined += !is_background(b.at(x, h / 2));
    apart += !is_background(a.at(x, h / 2));
  }
  EXPECT_EQ(apart, 0);
  EXPECT_GT(joined, 0);
  // both rods are drawn
  int rods = 0;
  for (int y = 0; y < h; ++y) rods += !is_background(a.at(w / 2, y));
  EXPECT_GT(rods, 10);
  const std::vector<rod::RodRange> bad = {{0, 60, false}, {60, 50, false}};
  EXPECT_THROW(render_rods(X, d1, bad, 20.0, standard_view("top"), w, h), std::invalid_argument);
}
}  // namespace
}  // namespace ibrod::render
