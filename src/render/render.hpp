#pragma once
// Pictures of the rod: a shaded tube of diameter D around the closed centreline X, with a stripe
// on the side the director D¹ points to, so that twist shows as a helical stripe. Software
// ray casting of one capsule (cylinder + spherical caps) per segment X_k → X_{k+1} (X_n = X_0)
// under an orthographic camera, nearest hit per pixel (a z-buffer), Lambert + ambient shading,
// dark outlines on the silhouette and where one part of the tube passes in front of a distant
// part (not where it turns toward the viewer in front of its own continuation), S×S
// supersampling. Knows
// points and directors only.
#include <span>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "render/image.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::render {

/// An orthographic camera: it looks along `forward`; `up` (not parallel to forward) sets the
/// image's upward direction. Image right = forward × up.
struct View {
  std::string name;
  Vec3 forward{0, 0, -1};
  Vec3 up{0, 1, 0};
};

/// The named views: "top" (down −z, x right, y up: the plane of the initial circle), "bottom",
/// "side" (along +y: x right, z up), "front" (along −x: y right, z up) and "oblique" (from above,
/// between x and −y). Unknown name: std::invalid_argument listing the names.
View standard_view(const std::string& name);
/// The names standard_view accepts, in a fixed order.
std::vector<std::string> standard_view_names();

/// What colours the tube's body: one colour with the D¹ stripe in a second; or a colour map
/// along the rod (point index: start blue → end red), of the lab height z, or of the twist
/// density (twist_density, the picture's lowest blue → highest red; uniform: green), with the
/// stripe a darker shade of the body.
enum class Colouring { stripe, along, height, twist };

/// The twist density of each segment X_k → X_{k+1} (X_n = X_0), in radians per unit of X's
/// length: D¹_k (made ⟂ to the vertex tangent t_k, central differences) parallel-transported to
/// t_{k+1} by the smallest rotation, then its signed angle (right-handed about t_{k+1}) to
/// D¹_{k+1}, over the segment's length (0 where the tangent turns by more than ~172°). X.size() ≥ 2
/// and d1.size() = X.size(), else std::invalid_argument.
std::vector<double> twist_density(std::span<const Vec3> X, std::span<const Vec3> d1);

struct Style {
  Colouring colouring = Colouring::stripe;
  Rgb background{255, 255, 255};
  Rgb tube{60, 105, 200};    ///< body colour (blue: b > r)
  Rgb stripe{240, 170, 30};  ///< stripe colour (orange: r > b)
  double stripe_cos = 0.8;   ///< the stripe: unit normal · D¹ (⟂ to the axis) above this
                             ///< (0.8: a band of ±37° about D¹, a fifth of the circumference)
  double ambient = 0.3;      ///< shade = ambient + (1 − ambient) max(0, n · light)
  double outline_darken = 0.45;  ///< shade factor of a ≈ 1 pixel outline on the near side of
                                 ///< occlusion boundaries (1: no outlines)
  double outline_arc = 2;  ///< an occluded neighbour gets an outline only when it is more than this
                           ///< many diameters away along the rod (a part that turns toward the
                           ///< viewer in front of its own continuation has none)
  int supersample = 3;     ///< S×S rays per pixel, averaged
  double margin = 0.04;    ///< free border on each side, fraction of the smaller image side
  double depth_cue = 0.35;  ///< the farthest tube surface is blended this far toward the background
  std::vector<std::string> labels;  ///< lines written at the top left (a band the rod stays out of)
  bool scale_bar = false;           ///< a bar of a round length at the bottom left, labelled in Å
  double scale_bar_length = 0;      ///< its length in X's unit (Å); 0: the round length nearest
                                    ///< below a quarter of the image width
  bool axis_triad = false;          ///< the lab axes x, y, z at the bottom right
  Rgb ink{40, 40, 40};              ///< labels, scale bar and axis triad
};

/// Renders the rods `rods` (rod::RodRange: offset, points, closed; laid one after another in X,
/// covering it), each its own tube of diameter `diameter` (X's length unit) about its polygon (a
/// closed one a ring; an open one with capped free ends; no segment joins two rods) with the
/// stripe along d1 (one director per point; interpolated along each segment and projected ⟂ to
/// it), seen from `view`, into a width × height image. Tight framing: the box that the tube
/// about the points `frame` (empty: X itself) covers on the image plane is centred and fills
/// the image less the margins along its limiting side (pass every frame of a movie as `frame`
/// so that all its pictures share one scale and centre). X.size() ≥ 2, d1.size() = X.size() and
/// the rods laid end to end over X, else std::invalid_argument.
Image render_rods(std::span<const Vec3> X, std::span<const Vec3> d1,
                  std::span<const rod::RodRange> rods, double diameter, const View& view, int width,
                  int height, const Style& style = {}, std::span<const Vec3> frame = {});
/// render_rods of one closed ring, the whole of X.
Image render_rod(std::span<const Vec3> X, std::span<const Vec3> d1, double diameter,
                 const View& view, int width, int height, const Style& style = {},
                 std::span<const Vec3> frame = {});

}  // namespace ibrod::render
