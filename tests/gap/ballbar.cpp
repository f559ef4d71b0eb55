// Gap diagnosis on ballbar traces: dr observations, directions, a centre shift, thermal growth.
#include <doctest/doctest.h>

#include "gap/fixtures.hpp"

using namespace weilgen;
using namespace weilgen::gap_test;

TEST_CASE("gap: ballbar traces are dr observations, and reversal on X is read from them") {
  const MeasurementTable t = parse_measurements(ballbar_synth(21, none), "bb.csv");
  const GapData d = gap_data(t, vmc()->description());
  REQUIRE(d.circle);
  CHECK(d.points.count[kRadialOutput] == 4 * 360);
  CHECK(d.covariate.count("feed") == 1);
  CHECK(d.covariate.count("angle_deg") == 1);
  // A dr row of the design matrix is the radial projection of the dx, dy, dz rows at its pose.
  PdgeBasisChoice c;
  c.all = "poly:2";
  const ErrorParameterisation p(vmc()->description(), c, vmc()->parameters());
  PointData pd;
  const PointObservation& dr = d.points.observations[37];
  pd.poses = {d.points.poses[dr.row]};
  for (int o = 0; o < 3; ++o) pd.observations.push_back({0, 0, o, 0.0, {}});
  PointObservation r = dr;
  r.row = 0;
  pd.observations.push_back(r);
  const Eigen::MatrixXd A = design_matrix(*vmc(), p, pd);
  const Eigen::RowVectorXd projected =
      dr.radial[0] * A.row(0) + dr.radial[1] * A.row(1) + dr.radial[2] * A.row(2);
  CHECK((A.row(3) - projected).norm() <= 1e-12 * A.row(3).norm());
  CHECK(std::hypot(dr.radial[0], dr.radial[1]) == doctest::Approx(1.0).epsilon(1e-12));

  // Bad traces: a missing circle key, an angle missing where dr is measured.
  std::string text = ballbar_synth(21, none, 1);
  std::string no_radius = text;
  no_radius.erase(no_radius.find("# radius"), no_radius.find('\n', no_radius.find("# radius")) -
                                                  no_radius.find("# radius") + 1);
  CHECK_THROWS_WITH(gap_data(parse_measurements(no_radius, "bb.csv"), vmc()->description()),
                    doctest::Contains("bb.csv:3: ballbar: the header key '# radius:' is missing"));
  const auto row7 = [&] {
    std::size_t at = 0;
    for (int k = 0; k < 6; ++k) at = text.find('\n', at) + 1;  // 3 keys, header, 2 rows
    return at;
  }();
  std::string no_angle = text;
  const std::size_t c4 = [&] {  // angle_deg: after the 4th comma of the row
    std::size_t at = row7;
    for (int k = 0; k < 4; ++k) at = no_angle.find(',', at) + 1;
    return at;
  }();
  no_angle.erase(c4, no_angle.find(',', c4) - c4);
  const std::string no_angle_message = "bb.csv:7:" + std::to_string(c4 - row7 + 1) +
                                       ": column 'angle_deg' is empty but dr_um is measured";
  CHECK_THROWS_WITH(gap_data(parse_measurements(no_angle, "bb.csv"), vmc()->description()),
                    no_angle_message.c_str());

  const MeasurementTable tr = parse_measurements(
      ballbar_synth(22,
                    [](const Row& w) {
                      return std::array<double, 3>{2.5 * w.dir_X, 0, 0};  // B = 5 µm in dx
                    }),
      "bb.csv");
  const GapResult res = GapDiagnosis().run(*vmc(), p, gap_data(tr, vmc()->description()),
                                           *parse_holdout("cycle:4"), "test");
  CHECK(res.verdict.names("reversal"));
  const EffectFit* e = effect(res, "reversal");
  REQUIRE(e);
  // X alone, or X and Y at once (the circle's both axes) with Y's at the noise.
  const bool both = e->params.count("reversal_um_X") == 1;
  CHECK(std::abs(e->params.at(both ? "reversal_um_X" : "reversal_um")) ==
        doctest::Approx(5.0).epsilon(0.1));
  if (both) CHECK(std::abs(e->params.at("reversal_um_Y")) < 0.5);
  CHECK(res.final.rms[kRadialOutput] < 1.2 * 0.4);
  // "where" along the trace's angle is in deg, the unit the measurement reader gives the
  // column (classify_column); the feed (ccw +1, cw -1) has none.
  CHECK(d.covariate_unit.at("angle_deg") == "deg");
  int angle = 0, feed = 0;
  for (const GapRegion& g : res.where) {
    if (g.by == "angle_deg") {
      CHECK(g.unit == "deg");
      ++angle;
    }
    if (g.by == "feed") {
      CHECK(g.unit.empty());
      ++feed;
    }
  }
  CHECK(angle >= 1);
  CHECK(feed >= 1);
}

TEST_CASE(
    "gap: a trace without dir columns still has its axes' directions: 6 um X and 4 um Y backlash "
    "are named") {
  // The issue-29 case: a trace gives angle_deg and the feed only. The directions of X and Y come
  // from the circle (ballbar_travel_direction), so `reversal` is a candidate. On vmc_3axis the
  // table carries X and Y: an axis short by dir B/2 moves the tool by +dir B/2 along x or y.
  const MeasurementTable t =
      parse_measurements(ballbar_synth(
                             24,
                             [](const Row& w) {
                               return std::array<double, 3>{3.0 * w.dir_X, 2.0 * w.dir_Y, 0};
                             },
                             4, 0.4, false, false),
                         "bb.csv");
  CHECK_FALSE(t.has("dir_X"));
  const GapData d = gap_data(t, vmc()->description());
  CHECK(d.derived_dir == std::vector<std::string>{"X", "Y"});
  REQUIRE(d.dir.count("X") == 1);
  // The derived directions equal the synthesiser's.
  const std::vector<double> with_column =
      parse_measurements(ballbar_synth(24, none, 4, 0.4, false, true), "b.csv").column("dir_X");
  CHECK(d.dir.at("X") == with_column);
  PdgeBasisChoice c;
  c.all = "poly:2";
  const ErrorParameterisation p(vmc()->description(), c, vmc()->parameters());
  const GapResult res = GapDiagnosis().run(*vmc(), p, d, *parse_holdout("cycle:4"), "test");
  CHECK(res.verdict.names("reversal"));
  // Both axes reverse on a circle: the variant of both at once, one size each.
  REQUIRE_FALSE(res.explanation.empty());
  const EffectFit& e = res.explanation.front();
  CHECK(e.name == "reversal");
  REQUIRE(e.params.count("reversal_um_X") == 1);
  REQUIRE(e.params.count("reversal_um_Y") == 1);
  CHECK(std::abs(e.params.at("reversal_um_X")) == doctest::Approx(6.0).epsilon(0.1));
  CHECK(std::abs(e.params.at("reversal_um_Y")) == doctest::Approx(4.0).epsilon(0.1));
  CHECK(res.final.rms[kRadialOutput] < 1.2 * 0.4);
}

TEST_CASE("gap: on a ballbar trace the lack of fit sees a step in y in time (a centre shift)") {
  // A 4 µm step in y (after 3 of 6 cycles) moves the circle's centre: dr changes by 4 sin θ,
  // which averages out over each of the time bins, whole cycles here as in the benchmark's
  // ballbar layouts, so a free offset of dr per bin did not see it (p = 1 here, and on the
  // benchmark's head_head_bc ballbar_yz step); free x, y, z offsets seen through u do.
  PdgeBasisChoice c;
  c.all = "poly:2";
  const ErrorParameterisation p(vmc()->description(), c, vmc()->parameters());
  auto run = [&](const EffectFn& fn) {
    const MeasurementTable t = parse_measurements(ballbar_synth(23, fn, 6), "bb.csv");
    return GapDiagnosis().run(*vmc(), p, gap_data(t, vmc()->description()),
                              *parse_holdout("cycle:4"), "test");
  };
  const GapResult step = run([](const Row& w) {
    return std::array<double, 3>{0, w.t_s >= 540 ? 4.0 : 0.0, 0};
  });
  CHECK(step.baseline_lack_of_fit_p < 1e-6);
  CHECK(step.baseline_lack_of_fit_along == "time");
  // Effect-free, the same test reads noise.
  const GapResult clean = run(none);
  CHECK(clean.baseline_lack_of_fit_p > 0.01);
  CHECK(clean.verdict.kind == GapVerdict::Kind::None);
}

TEST_CASE(
    "gap: a thermal growth on a ballbar trace with a spindle sensor is named (no empty "
    "variant: a growth along z that an XY trace cannot see)") {
  // dx grows by 2 µm/K of T_spindle; the trace sees it through cos θ.
  const MeasurementTable t =
      parse_measurements(ballbar_synth(
                             23,
                             [](const Row& w) {
                               return std::array<double, 3>{2.0 * (w.T - 22), 0, 0};
                             },
                             4, 0.4, true),
                         "bb.csv");
  PdgeBasisChoice c;
  c.all = "poly:2";
  const ErrorParameterisation p(vmc()->description(), c, vmc()->parameters());
  const GapResult res = GapDiagnosis().run(*vmc(), p, gap_data(t, vmc()->description()),
                                           *parse_holdout("cycle:4"), "test");
  CHECK(res.verdict.names("thermal_drift"));
  const EffectFit* e = effect(res, "thermal_drift");
  REQUIRE(e);
  CHECK(res.final.rms[kRadialOutput] < 1.2 * 0.4);
}
