// The time-scheme keys of issue 14: time.scheme takes "explicit" or "implicit" and nothing else,
// the implicit knobs reach SimParams in internal units, and every key is described.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "config/config.hpp"
#include "core/error.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

TEST(SchemeKeys, ExplicitByDefaultImplicitOnRequest) {
  config::Config c;
  EXPECT_EQ(config::to_params(c).scheme, sim::TimeScheme::explicit_step);
  config::apply_override(c, "time.scheme=\"implicit\"");
  config::apply_override(c, "time.max_displacement_A=1.5");
  config::apply_override(c, "time.energy_tolerance_kT=0.01");
  config::apply_override(c, "time.dt_min_ns=0.01");
  config::apply_override(c, "time.implicit_mobility_scale=6");
  config::apply_override(c, "time.implicit_jacobian_every=2");
  config::apply_override(c, "time.implicit_krylov_iterations=5");
  config::validate(c);
  EXPECT_EQ(config::to_params(c).implicit.order, 1);  // the default: the IMEX Euler step
  const sim::SimParams p = config::to_params(c);
  EXPECT_EQ(p.scheme, sim::TimeScheme::implicit_step);
  EXPECT_DOUBLE_EQ(p.adaptive.max_displacement, 1.5);
  EXPECT_DOUBLE_EQ(p.adaptive.energy_tolerance, 0.01 * p.kT);
  EXPECT_DOUBLE_EQ(p.adaptive.dt_min, 1e-11);
  EXPECT_DOUBLE_EQ(p.implicit.mobility_scale, 6);
  EXPECT_EQ(p.implicit.jacobian_every, 2);
  EXPECT_EQ(p.implicit.krylov_max_iter, 5);
  EXPECT_THAT(config::to_toml(c), HasSubstr("scheme = 'implicit'"));
  for (const char* k :
       {"time.scheme", "time.max_displacement_A", "time.energy_tolerance_kT", "time.dt_min_ns",
        "time.implicit_mobility_scale", "time.implicit_jacobian_every",
        "time.implicit_krylov_iterations", "time.implicit_krylov_tol"})
    EXPECT_THAT(config::describe(c), HasSubstr(k));
}

TEST(SchemeKeys, AnUnknownSchemeOrABadKnobNamesTheKey) {
  config::Config c;
  try {
    config::apply_override(c, "time.scheme=\"semi\"");
    FAIL() << "accepted time.scheme = \"semi\"";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("time.scheme"));
    EXPECT_THAT(e.what(), HasSubstr("implicit"));
  }
  EXPECT_THROW(config::apply_override(c, "time.scheme=1"), ConfigError);
  EXPECT_THROW(config::apply_override(c, "time.implicit_jacobian_every=0"), ConfigError);
  EXPECT_THROW(config::apply_override(c, "time.max_displacement_A=-1"), ConfigError);
  config::apply_override(c, "time.scheme=\"implicit\"");
  config::apply_override(c, "time.dt_min_ns=1");  // above time.dt_ns = 0.1
  EXPECT_THROW(config::validate(c), ConfigError);
}
TEST(SchemeKeys, TheOverlapLocalMobilityAndItsScaleReachTheParameters) {
  config::Config c;
  config::apply_override(c, "time.scheme=\"implicit\"");
  EXPECT_EQ(config::to_params(c).implicit.local_mobility,
            integrate::ImplicitParams::LocalMobility::self);
  EXPECT_DOUBLE_EQ(config::to_params(c).implicit.mobility_scale, 8);
  config::apply_override(c, "time.implicit_local_mobility=\"overlap\"");
  config::apply_override(c, "time.implicit_overlap_scale=0.5");
  config::validate(c);
  const sim::SimParams p = config::to_params(c);
  EXPECT_EQ(p.implicit.local_mobility, integrate::ImplicitParams::LocalMobility::overlap);
  EXPECT_DOUBLE_EQ(p.implicit.mobility_scale, 0.5);  // the overlap's scale, not the self one's
  EXPECT_EQ(p.implicit.jacobian_every, 50);          // the overlap's refresh
  config::apply_override(c, "time.implicit_overlap_refresh_every=3");
  EXPECT_EQ(config::to_params(c).implicit.jacobian_every, 3);
  EXPECT_DOUBLE_EQ(config::to_params(c).implicit.refresh_displacement, 1);  // Å, by default
  config::apply_override(c, "time.implicit_refresh_displacement_A=1.5");
  EXPECT_DOUBLE_EQ(config::to_params(c).implicit.refresh_displacement, 1.5);  // Å
  try {
    config::apply_override(c, "time.implicit_refresh_displacement_A=-1");
    FAIL() << "accepted a negative refresh displacement";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("time.implicit_refresh_displacement_A"));
    EXPECT_THAT(e.what(), HasSubstr("-1"));
  }
  EXPECT_THAT(config::to_toml(c), HasSubstr("implicit_local_mobility = 'overlap'"));
  for (const char* k :
       {"time.implicit_local_mobility", "time.implicit_overlap_scale",
        "time.implicit_overlap_refresh_every", "time.implicit_refresh_displacement_A"})
    EXPECT_THAT(config::describe(c), HasSubstr(k));
  try {
    config::apply_override(c, "time.implicit_local_mobility=\"banded\"");
    FAIL() << "accepted banded";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("time.implicit_local_mobility"));
    EXPECT_THAT(e.what(), HasSubstr("\"overlap\""));
  }
  EXPECT_THROW(config::apply_override(c, "time.implicit_overlap_scale=0"), ConfigError);
  // a grid on which two kernels would overlap both ways round the box
  config::apply_override(c, "time.implicit_local_mobility=\"overlap\"");
  config::apply_override(c, "grid.n=10");
  try {
    config::validate(c);
    FAIL() << "accepted the overlap on a 10³ grid";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("time.implicit_local_mobility"));
    EXPECT_THAT(e.what(), HasSubstr("grid.n = 10"));
  }
}

TEST(SchemeKeys, OrderTwoAndItsErrorToleranceReachTheParameters) {
  config::Config c;
  config::apply_override(c, "time.scheme=\"implicit\"");
  config::apply_override(c, "time.implicit_order=2");
  config::apply_override(c, "time.error_tolerance_A=0.05");
  config::validate(c);
  sim::SimParams p = config::to_params(c);
  EXPECT_EQ(p.implicit.order, 2);
  EXPECT_DOUBLE_EQ(p.adaptive.error_tolerance, 0.05);
  // order 1 has no estimate: no error control
  config::apply_override(c, "time.implicit_order=1");
  EXPECT_EQ(config::to_params(c).adaptive.error_tolerance, 0.0);
  // with order 2, GMRES solves ROS2's stages on the true mobility (docs/large_dt.md §10)
  config::apply_override(c, "time.implicit_order=2");
  config::apply_override(c, "time.implicit_krylov_iterations=3");
  config::validate(c);
  p = config::to_params(c);
  EXPECT_EQ(p.implicit.order, 2);
  EXPECT_EQ(p.implicit.krylov_max_iter, 3);
  EXPECT_DOUBLE_EQ(p.adaptive.error_tolerance, 0.05);
  EXPECT_EQ(p.implicit.krylov_error_budget, 0.0);  // off by default
  // the GMRES residual's share of the error tolerance (docs/large_dt.md §13): a length, Å
  config::apply_override(c, "time.implicit_krylov_error_share=0.3");
  EXPECT_DOUBLE_EQ(config::to_params(c).implicit.krylov_error_budget, 0.3 * 0.05);
  config::apply_override(c, "time.implicit_order=1");  // no error control, no budget
  EXPECT_EQ(config::to_params(c).implicit.krylov_error_budget, 0.0);
  config::apply_override(c, "time.implicit_order=2");
  for (const char* bad : {"-0.1", "1.5", "nan"}) {
    try {
      config::apply_override(c, std::string("time.implicit_krylov_error_share=") + bad);
      FAIL() << "accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_THAT(e.what(), HasSubstr("time.implicit_krylov_error_share")) << bad;
    }
  }
  EXPECT_THAT(config::describe(c), HasSubstr("time.implicit_krylov_error_share"));
  config::apply_override(c, "time.implicit_krylov_iterations=0");
  EXPECT_THROW(config::apply_override(c, "time.implicit_order=3"), std::exception);
}

// time.stability_method (docs/config.md "The stability test"): "auto" (the default: the Hessian up
// to 1000 rod points, the dynamic test above), "dynamic" or "hessian"; anything else, and the
// dense Hessian asked for on more than 1500 points, is refused naming the key, the value and what
// is allowed.
TEST(SchemeKeys, TheStabilityMethodIsAutoDynamicOrHessianAndTheHessianHasASizeLimit) {
  config::Config c;
  EXPECT_THAT(config::describe(c), HasSubstr("time.stability_method = \"auto\""));
  using M = sim::StabilityProbe::Method;
  EXPECT_EQ(config::to_params(c).stability.method, M::hessian);  // the 600-point reference ring
  config::apply_override(c, "rod.base_pairs=1000");
  EXPECT_EQ(config::to_params(c).stability.method, M::hessian);
  config::apply_override(c, "rod.base_pairs=1001");
  EXPECT_EQ(config::to_params(c).stability.method, M::dynamic);
  config::apply_override(c, "rod.base_pairs=600");
  config::apply_override(c, "time.stability_method=\"dynamic\"");
  EXPECT_EQ(config::to_params(c).stability.method, M::dynamic);
  config::apply_override(c, "time.stability_method=\"hessian\"");
  EXPECT_EQ(config::to_params(c).stability.method, M::hessian);
  EXPECT_THAT(config::describe(c), HasSubstr("time.stability_method = \"hessian\""));
  for (const char* bad : {"\"lanczos\"", "1", "true"}) {
    try {
      config::apply_override(c, std::string("time.stability_method=") + bad);
      FAIL() << "accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_THAT(e.what(), HasSubstr("time.stability_method")) << bad;
      EXPECT_THAT(e.what(), HasSubstr("\"auto\", \"dynamic\" or \"hessian\"")) << bad;
    }
  }
  config::apply_override(c, "rod.base_pairs=2000");
  config::apply_override(c, "grid.box_A=2400");
  try {
    config::to_params(c);
    FAIL() << "the Hessian on 2000 points was accepted";
  } catch (const ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("time.stability_method"));
    EXPECT_THAT(e.what(), HasSubstr("1500"));
    EXPECT_THAT(e.what(), HasSubstr("2000"));
  }
  config::apply_override(c, "time.stability_method=\"auto\"");  // auto: the dynamic test there
  EXPECT_EQ(config::to_params(c).stability.method, M::dynamic);
  config::apply_override(c, "time.stability_method=\"hessian\"");
  config::apply_override(c, "time.stability_test=false");  // no test: no Hessian to refuse
  EXPECT_NO_THROW(config::to_params(c));
}
