// Ballbar circle prediction and evaluation (weilgen/measure/ballbar.hpp, docs/ballbar.md):
// closed-form traces of a centre offset, a squareness, scale errors and a constant tangential
// deviation; feed order; the vmc_3axis model against the closed form and the exact numeric chain;
// the circle's header keys and flags with their messages; measured traces; the comparison; and the
// synthetic example file against an independent generator.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "test_support.hpp"
#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model.hpp"
#include "weilgen/model/model_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;

namespace {

constexpr double kPi = 3.14159265358979323846;

double rad(double deg) { return deg * kPi / 180; }

const BallbarMachine& xyz() {
  static const BallbarMachine m = ballbar_machine_by_letters({"X", "Y", "Z"});
  return m;
}

BallbarCircle circle_xy(double cx, double cy, double r, int feed = 1) {
  BallbarCircle c;
  c.plane = "XY";
  c.first = "X";
  c.second = "Y";
  c.centre = {{"X", cx}, {"Y", cy}, {"Z", 0.0}};
  c.radius_mm = r;
  c.feed = feed;
  return c;
}

// A deviation (mm) that is a function of the pose (X, Y, Z).
DeviationFn position_fn(std::function<std::array<double, 3>(double, double, double)> f) {
  return [f](const double* q, double* out6) {
    const auto d = f(q[0], q[1], q[2]);
    for (int k = 0; k < 3; ++k) out6[k] = d[static_cast<std::size_t>(k)];
    out6[3] = out6[4] = out6[5] = 0;
  };
}

std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

std::string arg_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no invalid_argument";
}

std::shared_ptr<Model> vmc_model() { return test::builtin_model("vmc_3axis"); }

// Zhang & Chen 2021's circle (section 4).
BallbarCircle seed_circle(const BallbarMachine& m) {
  BallbarFlags f;
  f.plane = "XY";
  f.centre = "X=343.507, Y=-285.090, Z=-286.430";
  f.radius = "100 mm";
  return parse_ballbar_circle(f, m);
}

}  // namespace

TEST_CASE("ballbar: a constant centre offset is a cos θ trace, removed by the LSQ centre") {
  const double a0 = 0.004;  // mm
  const BallbarCircle c = circle_xy(120, -40, 75);
  const BallbarTrace t = predict_ballbar(xyz(), c, position_fn([&](double, double, double) {
                                           return std::array<double, 3>{a0, 0, 0};
                                         }));
  REQUIRE(t.size() == 360);
  for (std::size_t k = 0; k < t.size(); ++k) {
    CHECK(t.angle_deg[k] == doctest::Approx(static_cast<double>(k)));
    CHECK(t.dr_um[k] == doctest::Approx(4.0 * std::cos(rad(t.angle_deg[k]))).epsilon(1e-12));
  }
  const BallbarEvaluation e = evaluate_ballbar(t, c.radius_mm);
  CHECK(e.centre_offset_um[0] == doctest::Approx(4.0).epsilon(1e-12));
  CHECK(std::abs(e.centre_offset_um[1]) < 1e-12);
  CHECK(std::abs(e.radius_deviation_um) < 1e-12);
  CHECK(e.circular_deviation_um < 1e-11);
  CHECK(e.max_minus_min_um == doctest::Approx(8.0).epsilon(1e-12));  // 2|a0|: θ = 0 and 180
  CHECK(e.coverage_deg == doctest::Approx(359.0));
  REQUIRE(e.harmonics.size() == 3);
  for (const BallbarHarmonic& h : e.harmonics) CHECK(h.amplitude_um < 1e-12);
}

TEST_CASE("ballbar: squareness dx = S·y gives (S R/2) sin 2θ and G = S R") {
  const double s = 20e-6, r = 80, cy = 50;
  const BallbarCircle c = circle_xy(100, cy, r);
  const BallbarTrace t = predict_ballbar(xyz(), c, position_fn([&](double, double y, double) {
                                           return std::array<double, 3>{s * y, 0, 0};
                                         }));
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double th = rad(t.angle_deg[k]);
    const double expect = 1000 * (s * cy * std::cos(th) + s * r / 2 * std::sin(2 * th));
    CHECK(t.dr_um[k] == doctest::Approx(expect).scale(1.0).epsilon(1e-12));
  }
  const BallbarEvaluation e = evaluate_ballbar(t, r);
  CHECK(e.circular_deviation_um == doctest::Approx(1000 * s * r).epsilon(1e-12));  // 1.6 µm
  CHECK(e.centre_offset_um[0] == doctest::Approx(1000 * s * cy).epsilon(1e-12));   // S·c_y
  CHECK(std::abs(e.centre_offset_um[1]) < 1e-12);
  CHECK(e.radial_deviation_max_um == doctest::Approx(0.8).epsilon(1e-12));
  CHECK(e.radial_deviation_min_um == doctest::Approx(-0.8).epsilon(1e-12));
  REQUIRE(!e.harmonics.empty());
  CHECK(e.harmonics[0].order == 2);
  CHECK(e.harmonics[0].sin_um == doctest::Approx(0.8).epsilon(1e-12));
  CHECK(std::abs(e.harmonics[0].cos_um) < 1e-12);
  CHECK(e.harmonics[0].phase_deg == doctest::Approx(45.0));  // 0.8 cos(2(θ − 45°))
  CHECK(e.squareness_urad == doctest::Approx(20.0).epsilon(1e-12));
  CHECK(std::abs(e.scale_mismatch_um_per_m) < 1e-9);
}

TEST_CASE("ballbar: scale errors change the radius, and a scale mismatch is a cos 2θ term") {
  const double k = 10e-6, r = 150, cx = 200, cy = -100;
  const BallbarCircle c = circle_xy(cx, cy, r);
  SUBCASE("equal scale dx = k x, dy = k y: radius deviation k R, centre offset k c, G = 0") {
    const BallbarEvaluation e =
        evaluate_ballbar(predict_ballbar(xyz(), c, position_fn([&](double x, double y, double) {
                                           return std::array<double, 3>{k * x, k * y, 0};
                                         })),
                         r);
    CHECK(e.radius_deviation_um == doctest::Approx(1000 * k * r).epsilon(1e-12));  // 1.5 µm
    CHECK(e.centre_offset_um[0] == doctest::Approx(1000 * k * cx).epsilon(1e-12));
    CHECK(e.centre_offset_um[1] == doctest::Approx(1000 * k * cy).epsilon(1e-12));
    CHECK(e.circular_deviation_um < 1e-11);
    CHECK(std::abs(e.scale_mismatch_um_per_m) < 1e-9);
  }
  SUBCASE("X only, dx = k x: k R/2 radius, (k R/2) cos 2θ, mismatch k") {
    const BallbarEvaluation e =
        evaluate_ballbar(predict_ballbar(xyz(), c, position_fn([&](double x, double, double) {
                                           return std::array<double, 3>{k * x, 0, 0};
                                         })),
                         r);
    CHECK(e.radius_deviation_um == doctest::Approx(500 * k * r).epsilon(1e-12));
    CHECK(e.circular_deviation_um == doctest::Approx(1000 * k * r).epsilon(1e-12));
    CHECK(e.scale_mismatch_um_per_m == doctest::Approx(10.0).epsilon(1e-12));
    CHECK(std::abs(e.squareness_urad) < 1e-9);
    CHECK(e.harmonics[0].cos_um == doctest::Approx(500 * k * r).epsilon(1e-12));
  }
}

TEST_CASE("ballbar: cw and ccw give the same geometric trace in reverse order") {
  const DeviationFn f = position_fn([](double x, double y, double z) {
    return std::array<double, 3>{1e-3 * std::sin(x / 37), 2e-3 * std::cos(y / 23) + 1e-6 * x,
                                 1e-4 * z};
  });
  const BallbarTrace ccw = predict_ballbar(xyz(), circle_xy(10, 20, 60, 1), f);
  const BallbarTrace cw = predict_ballbar(xyz(), circle_xy(10, 20, 60, -1), f);
  CHECK(ccw.feed == 1);
  CHECK(cw.feed == -1);
  REQUIRE(cw.size() == ccw.size());
  const std::size_t n = ccw.size();
  CHECK(cw.angle_deg[1] == 359.0);
  for (std::size_t i = 0; i < n; ++i) {
    CHECK(cw.angle_deg[i] == ccw.angle_deg[(n - i) % n]);
    CHECK(cw.dr_um[i] == ccw.dr_um[(n - i) % n]);
  }
  const double g_ccw = evaluate_ballbar(ccw, 60).circular_deviation_um;
  CHECK(evaluate_ballbar(cw, 60).circular_deviation_um == doctest::Approx(g_ccw).epsilon(1e-12));
  CHECK(circular_hysteresis_um(ccw, cw) < 1e-12);
}

TEST_CASE("ballbar: the exact projection and the first-order bound") {
  // A constant deviation t along +y (large, to see the second order): exact
  // dr = sqrt(R² + 2 R t sin θ + t²) − R; first order t sin θ.
  const double t = 0.5, r = 100;
  const BallbarCircle c = circle_xy(0, 0, r);
  const DeviationFn f = position_fn([&](double, double, double) {
    return std::array<double, 3>{0, t, 0};
  });
  const BallbarTrace lin = predict_ballbar(xyz(), c, f, 72);
  const BallbarTrace exact = predict_ballbar(xyz(), c, f, 72, RadialProjection::Exact);
  for (std::size_t k = 0; k < lin.size(); ++k) {
    const double th = rad(lin.angle_deg[k]);
    const double closed = 1000 * (std::sqrt(r * r + 2 * r * t * std::sin(th) + t * t) - r);
    CHECK(exact.dr_um[k] == doctest::Approx(closed).scale(1.0).epsilon(1e-9));
    CHECK(lin.dr_um[k] == doctest::Approx(1000 * t * std::sin(th)).scale(1.0).epsilon(1e-12));
    const double dt = t * std::cos(th), dr = t * std::sin(th);  // mm
    const double gap_um = exact.dr_um[k] - lin.dr_um[k];
    CHECK(gap_um >= -1e-9);
    CHECK(gap_um <= 1000 * dt * dt / (2 * (r + dr)) + 1e-9);
  }
}

TEST_CASE("ballbar: vmc_3axis with a squareness E_C0Y: G = S R, signs of a table-moving machine") {
  const auto model = vmc_model();
  REQUIRE(model->engine() == ModelEngine::BuiltIn);
  const BallbarMachine m = ballbar_machine(*model);
  CHECK(m.coordinates == std::vector<std::string>{"Y", "X", "Z"});
  const BallbarCircle c = seed_circle(m);
  CHECK(c.centre.at("Y") == -285.090);
  const Description& d = model->description();
  const double s = 15e-6;  // rad
  std::vector<double> errors(model->num_errors(), 0.0);
  errors[static_cast<std::size_t>(d.error_index("E_C0Y"))] = s;

  const BallbarTrace t = predict_ballbar(m, c, model_deviation(model, errors));
  const BallbarEvaluation e = evaluate_ballbar(t, c.radius_mm);
  CHECK(e.circular_deviation_um == doctest::Approx(1000 * s * 100).epsilon(1e-9));  // 1.5 µm
  // The table carries X and Y: the tool moves relative to the workpiece along -x, -y, so the
  // model's dx = S·Y is -S·Y along the X coordinate's direction: the centre moves by -S·c_y
  // along X and the ballbar reads the squareness as -S.
  CHECK(e.centre_offset_um[0] == doctest::Approx(-1000 * s * -285.090).epsilon(1e-9));
  CHECK(std::abs(e.centre_offset_um[1]) < 1e-9);
  CHECK(e.squareness_urad == doctest::Approx(-15.0).epsilon(1e-9));

  // Independent check against the exact numeric chain: |P(q) − P(centre)| − R with the error.
  NumericChain chain(d);
  const std::vector<double> zero(d.errors.size(), 0.0);
  const std::vector<double> qc{-285.090, 343.507, -286.430};
  const Eigen::Vector3d pc = chain.tool_in_workpiece(qc, zero).block<3, 1>(0, 3);
  for (std::size_t k = 0; k < t.size(); k += 17) {
    const std::vector<double> q = ballbar_pose(m, c, t.angle_deg[k]);
    const Eigen::Vector3d p = chain.tool_in_workpiece(q, errors).block<3, 1>(0, 3);
    // Differences: second order in the error, ~1e-4 µm here.
    CHECK(t.dr_um[k] == doctest::Approx(1000 * ((p - pc).norm() - 100)).scale(1.0).epsilon(1e-3));
  }

  // A positioning error E_XX: the table overshoots along +X, the circle's centre follows.
  std::vector<double> exx(model->num_errors(), 0.0);
  exx[static_cast<std::size_t>(d.error_index("E_XX"))] = 0.002;
  const BallbarEvaluation ex =
      evaluate_ballbar(predict_ballbar(m, c, model_deviation(model, exx)), 100);
  CHECK(ex.centre_offset_um[0] == doctest::Approx(2.0).epsilon(1e-9));
  CHECK(ex.circular_deviation_um < 1e-9);
}

TEST_CASE("ballbar: poses and angles") {
  const auto model = vmc_model();
  const BallbarMachine m = ballbar_machine(*model);
  BallbarCircle c = seed_circle(m);
  const std::vector<double> q = ballbar_pose(m, c, 90);  // Y, X, Z
  CHECK(q[0] == doctest::Approx(-285.090 + 100));
  CHECK(q[1] == doctest::Approx(343.507));
  CHECK(q[2] == -286.430);
  c.feed = -1;
  c.start_angle_deg = 90;
  CHECK(ballbar_angles(c, 4) == std::vector<double>{90, 0, 270, 180});
  // A rotary axis cannot be in the plane; a plane built by hand is checked too.
  BallbarCircle bad = c;
  bad.first = "X";
  bad.second = "Q";
  CHECK(arg_error([&] { ballbar_pose(m, bad, 0); }) ==
        "ballbar: plane \"X,Q\" is not two distinct coordinates (the machine's coordinates: Y, "
        "X, Z)");
  // Without kinematics the letter rule must know the coordinates.
  const BallbarMachine uv = ballbar_machine_by_letters({"X1", "X2"});
  BallbarFlags f;
  f.plane = "X1,X2";
  f.centre = "X1=0";
  f.radius = "10";
  const BallbarCircle cu = parse_ballbar_circle(f, uv);
  CHECK(cu.plane == "X1X2");
  CHECK(arg_error([&] {
          predict_ballbar(uv, cu, position_fn([](double, double, double) {
                            return std::array<double, 3>{0, 0, 0};
                          }));
        }) ==
        "ballbar: no nominal direction for coordinate 'X1' (the letter rule knows X, Y, Z, "
        "U, V, W): build the BallbarMachine from the machine description");
}

TEST_CASE("ballbar: nominal kinematics set the radial direction and must give a circle") {
  // A table carrying X (the tool moves along -x as X grows): a constant dx = +a0 is a centre
  // offset of -a0 along X.
  BallbarMachine table_x = ballbar_machine_by_letters({"X", "Y", "Z"});
  table_x.nominal = [](const double* q, double* p) {
    p[0] = -q[0];
    p[1] = q[1];
    p[2] = q[2];
  };
  const DeviationFn dx = position_fn([](double, double, double) {
    return std::array<double, 3>{0.001, 0, 0};
  });
  const BallbarEvaluation e =
      evaluate_ballbar(predict_ballbar(table_x, circle_xy(0, 0, 50), dx), 50);
  CHECK(e.centre_offset_um[0] == doctest::Approx(-1.0).epsilon(1e-12));
  // A 0.1 % scale difference in the nominal kinematics is rejected.
  BallbarMachine stretched = table_x;
  stretched.nominal = [](const double* q, double* p) {
    p[0] = 1.001 * q[0];
    p[1] = q[1];
    p[2] = q[2];
  };
  CHECK(arg_error([&] { predict_ballbar(stretched, circle_xy(0, 0, 50), dx); }) ==
        "ballbar: the nominal motions of X and Y are not orthogonal unit vectors in the workpiece "
        "frame (|e_X| = 1.001, |e_Y| = 1, cos = 0): the programmed circle is not a circle");
  // A nominal path that bends (quadratic in X) is not a circle either.
  BallbarMachine bent = table_x;
  bent.nominal = [](const double* q, double* p) {
    p[0] = q[0];
    p[1] = q[1] + 1e-4 * q[0] * q[0];
    p[2] = q[2];
  };
  CHECK(arg_error([&] { predict_ballbar(bent, circle_xy(0, 0, 50), dx, 4); }) ==
        "ballbar: the nominal path of the tool relative to the workpiece is not a circle at θ = "
        "0° (off by 0.25 mm)");
}

TEST_CASE("ballbar: the circle from header keys and flags") {
  const BallbarMachine m = ballbar_machine(*vmc_model());
  const MeasurementTable t = parse_measurements(
      "# plane: XY\n"
      "# centre: X=250, Y=-200, Z=-100\n"
      "# radius: 150 mm\n"
      "# feed: cw\n"
      "angle_deg,dr_um\n"
      "0,1\n",
      "b.csv");
  const BallbarCircle c = parse_ballbar_circle(t, m);
  CHECK(c.plane == "XY");
  CHECK(c.first == "X");
  CHECK(c.second == "Y");
  CHECK(c.centre == std::map<std::string, double>{{"X", 250}, {"Y", -200}, {"Z", -100}});
  CHECK(c.radius_mm == 150);
  CHECK(c.feed == -1);
  CHECK(c.sources.at("radius").str() == "b.csv:3");
  CHECK(c.sources.at("feed").line == 4);

  BallbarFlags f;
  f.plane = "ZX";
  f.radius = "0.1 m";
  f.feed = "CCW";
  const BallbarCircle o = parse_ballbar_circle(t, m, f);
  CHECK(o.first == "Z");
  CHECK(o.second == "X");
  CHECK(o.radius_mm == doctest::Approx(100));
  CHECK(o.feed == 1);
  CHECK(o.sources.at("plane").str() == "--plane");
  CHECK(o.sources.at("centre").str() == "b.csv:2");

  // Centre values with units; coordinates not named are 0; the spelling "center".
  const BallbarCircle u = parse_ballbar_circle(
      parse_measurements(
          "# plane: X Y\n# center: X=0.25m, Y=-200\n# radius: 50\nangle_deg,dr_um\n0,1\n", "u.csv"),
      m);
  CHECK(u.centre == std::map<std::string, double>{{"X", 250}, {"Y", -200}, {"Z", 0}});
  CHECK(u.feed == 1);
  CHECK(u.sources.count("feed") == 0);
}

TEST_CASE("ballbar: bad circle settings name the file and line") {
  auto header_error = [](const std::string& keys, const BallbarMachine& m) {
    return input_error([&] {
      parse_ballbar_circle(parse_measurements(keys + "angle_deg,dr_um\n0,1\n", "b.csv"), m);
    });
  };
  const BallbarMachine& m = xyz();
  CHECK(header_error("# plane: XY\n# centre: X=0, Y=0\n", m) ==
        "b.csv:3: ballbar: the header key '# radius:' is missing (the nominal radius, e.g. "
        "'# radius: 150 mm'; or --radius)");
  CHECK(header_error("# centre: X=0\n# radius: 10\n", m) ==
        "b.csv:3: ballbar: the header key '# plane:' is missing (the circle's plane, e.g. "
        "'# plane: XY'; or --plane)");
  CHECK(header_error("# plane: XY\n# centre: X=0, Y=0\n# radius: 0 mm\n", m) ==
        "b.csv:3: ballbar: '# radius: 0 mm': the radius must be > 0");
  CHECK(header_error("# plane: XY\n# centre: X=0\n# radius: 5 deg\n", m) ==
        "b.csv:3: ballbar: '# radius: 5 deg': the radius is a length, \"deg\" is an angle unit");
  CHECK(header_error("# plane: XX\n# centre: X=0\n# radius: 10\n", m) ==
        "b.csv:1: ballbar: '# plane: XX': the plane needs two distinct coordinates (e.g. XY)");
  CHECK(header_error("# plane: XQ\n# centre: X=0\n# radius: 10\n", m) ==
        "b.csv:1: ballbar: '# plane: XQ': not two coordinates of the machine (the machine's "
        "coordinates: X, Y, Z; e.g. XY)");
  CHECK(header_error("# plane: XY\n# centre: X=0, Q=1\n# radius: 10\n", m) ==
        "b.csv:2: ballbar: '# centre: X=0, Q=1': unknown coordinate 'Q' (the machine's "
        "coordinates: X, Y, Z)");
  CHECK(header_error("# plane: XY\n# centre: X=0, X=1\n# radius: 10\n", m) ==
        "b.csv:2: ballbar: '# centre: X=0, X=1': X is given twice");
  CHECK(header_error("# plane: XY\n# centre: X 0\n# radius: 10\n", m) ==
        "b.csv:2: ballbar: '# centre: X 0': \"X 0\" is not NAME=value (NAME=value, ..., e.g. "
        "X=250, Y=0, Z=-100)");
  CHECK(header_error("# plane: XY\n# centre: X=0\n# radius: 10\n# feed: up\n", m) ==
        "b.csv:4: ballbar: '# feed: up': the feed is ccw (counter-clockwise, θ increasing) or cw");
  CHECK(header_error("# plane: XY\n# centre: X=0\n# center: Y=0\n# radius: 10\n", m) ==
        "b.csv:3: ballbar: '# center:' and '# centre:' are the same setting; give one");

  BallbarMachine rotary = ballbar_machine_by_letters({"X", "C"});
  rotary.prismatic[1] = false;
  rotary.units[1] = "deg";
  rotary.to_base[1] = kPi / 180;
  CHECK(header_error("# plane: XC\n# centre: X=0\n# radius: 10\n", rotary) ==
        "b.csv:1: ballbar: '# plane: XC': C is a rotary axis: a ballbar circle needs two linear "
        "axes");
  CHECK(header_error("# plane: X,X\n# centre: C=1mm\n# radius: 10\n", rotary) ==
        "b.csv:1: ballbar: '# plane: X,X': the plane needs two distinct coordinates (e.g. XY)");

  // Travel ranges (vmc_3axis: X in [0, 500]).
  const BallbarMachine vmc = ballbar_machine(*vmc_model());
  CHECK(header_error("# plane: XY\n# centre: X=450, Y=-200\n# radius: 100\n", vmc) ==
        "b.csv:3: ballbar: '# radius: 100': the circle leaves the range of X [0, 500] mm: "
        "450 ± 100 mm");
  CHECK(header_error("# plane: XY\n# centre: X=250, Y=-200, Z=5\n# radius: 100\n", vmc) ==
        "b.csv:2: ballbar: '# centre: X=250, Y=-200, Z=5': Z = 5 mm is outside the axis range "
        "[-300, 0] mm");

  // Flags are std::invalid_argument naming the flag.
  BallbarFlags f;
  f.plane = "XY";
  f.centre = "X=0";
  f.radius = "-5";
  CHECK(arg_error([&] { parse_ballbar_circle(f, m); }) ==
        "--radius: \"-5\": the radius must be > 0");
  f.radius = "5";
  f.centre = "";
  CHECK(arg_error([&] { parse_ballbar_circle(f, m); }) ==
        "ballbar: --centre is required (the circle's centre, e.g. --centre \"X=250, Y=0, "
        "Z=-100\")");
}

TEST_CASE("ballbar: measured traces from a table") {
  const std::string head = "# plane: XY\n# centre: X=0, Y=0\n# radius: 100\n# feed: cw\n";
  const MeasurementTable t = parse_measurements(head +
                                                    "angle_deg,dr_um,dir,cycle\n"
                                                    "0,1.0,1,1\n"
                                                    "90,2.0,1,1\n"
                                                    "180,,1,1\n"
                                                    "0,1.5,-1,1\n"
                                                    "270,2.5,,1\n"
                                                    "90,3.0,1,2\n",
                                                "t.csv");
  const BallbarCircle c = parse_ballbar_circle(t, xyz());
  const std::vector<BallbarTrace> traces = ballbar_traces(t, c);
  REQUIRE(traces.size() == 3);
  CHECK(traces[0].feed == 1);
  CHECK(traces[0].cycle == 1);
  CHECK(traces[0].angle_deg == std::vector<double>{0, 90});  // the empty dr_um is skipped
  CHECK(traces[0].lines == std::vector<int>{6, 7});
  CHECK(traces[1].feed == -1);  // dir -1, and the row without dir takes '# feed: cw'
  CHECK(traces[1].dr_um == std::vector<double>{1.5, 2.5});
  CHECK(traces[2].cycle == 2);

  CHECK(input_error([&] {
          ballbar_traces(parse_measurements(head + "angle_deg,dr_um\n0,1\n,2\n", "t.csv"), c);
        }) ==
        "t.csv:7:1: ballbar: angle_deg is empty in a row with dr_um (every measured point "
        "needs its angle)");
  CHECK(input_error([&] {
          ballbar_traces(parse_measurements(head + "angle_deg,dx_um\n0,1\n", "t.csv"), c);
        }) == "t.csv: missing column 'dr_um' (columns: angle_deg, dx_um)");
  CHECK(input_error([&] {
          ballbar_traces(parse_measurements(head + "angle_deg,dr_um\n0,\n", "t.csv"), c);
        }) == "t.csv:5: ballbar: no measured points (every dr_um cell is empty)");
}

TEST_CASE("ballbar: comparison with a measured trace") {
  // Prediction at 1° steps; "measurement" at the half degrees = the same geometry plus a set-up
  // offset (1.0, -0.5) µm.
  const double s = 20e-6, r = 100;
  const BallbarCircle c = circle_xy(0, 30, r);
  const DeviationFn f = position_fn([&](double, double y, double) {
    return std::array<double, 3>{s * y, 0, 0};
  });
  const BallbarTrace predicted = predict_ballbar(xyz(), c, f);
  BallbarTrace measured;
  for (int k = 0; k < 360; ++k) measured.angle_deg.push_back(k + 0.5);
  const BallbarTrace exact = predict_ballbar_at(xyz(), c, f, measured.angle_deg);
  for (std::size_t k = 0; k < 360; ++k) {
    const double th = rad(measured.angle_deg[k]);
    measured.dr_um.push_back(exact.dr_um[k] + 1.0 * std::cos(th) - 0.5 * std::sin(th));
  }
  const BallbarComparison cmp = compare_ballbar(measured, predicted, r);
  // Linear interpolation of A sin 2θ over 1° steps errs by at most A·4·h²/8 = 1.5e-4 µm here.
  CHECK(cmp.raw.rms_um == doctest::Approx(std::sqrt((1.0 + 0.25) / 2)).epsilon(1e-3));
  CHECK(cmp.raw.max_abs_um == doctest::Approx(std::sqrt(1.25)).epsilon(1e-3));
  CHECK(cmp.centred.rms_um < 2e-4);
  CHECK(cmp.centred.max_abs_um < 3e-4);
  CHECK(cmp.centred.correlation > 0.99999);
  CHECK(cmp.raw.correlation < cmp.centred.correlation);
  CHECK(cmp.difference.centre_offset_um[0] == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(cmp.difference.centre_offset_um[1] == doctest::Approx(-0.5).epsilon(1e-3));
  CHECK(cmp.difference.circular_deviation_um < 5e-4);  // Zhang & Chen 2021's "ideal compensation"
  CHECK(cmp.measured.circular_deviation_um ==
        doctest::Approx(cmp.predicted.circular_deviation_um).epsilon(1e-3));
  // At the measured angles the prediction is used as is: no interpolation error.
  const BallbarComparison same = compare_ballbar(measured, exact, r);
  CHECK(same.centred.max_abs_um < 1e-12);

  BallbarTrace half;
  for (int k = 0; k <= 18; ++k) {
    half.angle_deg.push_back(10.0 * k);
    half.dr_um.push_back(0.0);
  }
  CHECK(arg_error([&] { interpolate_trace(half, {45}); }) ==
        "ballbar: the trace has a gap of 180 deg after 180 deg (more than 15 deg): it does not "
        "cover the circle");
  // A half circle still has a centre fit, but no harmonics and no NaN figures elsewhere.
  const BallbarEvaluation he = evaluate_ballbar(half, r);
  CHECK(he.coverage_deg == doctest::Approx(180));
  CHECK(he.harmonics.empty());
  CHECK(std::isnan(he.squareness_urad));
  CHECK(arg_error([&] {
          evaluate_ballbar({0, 0, 360}, {1, 2, 3}, r);
        }) == "ballbar: 1 distinct angles: the centre fit needs at least 3");
}

TEST_CASE("ballbar: the synthetic example file against its generator's error set") {
  const auto model = vmc_model();
  const Description& d = model->description();
  const BallbarMachine m = ballbar_machine(*model);
  const MeasurementTable t =
      read_measurements(std::string(WEILGEN_SOURCE_DIR) + "/examples/data/ballbar_xy.csv");
  const BallbarCircle c = parse_ballbar_circle(t, m);
  CHECK(c.radius_mm == 100);
  const std::vector<BallbarTrace> traces = ballbar_traces(t, c);
  REQUIRE(traces.size() == 2);
  CHECK(traces[0].feed == 1);
  CHECK(traces[1].feed == -1);
  CHECK(traces[1].size() == 360);

  // The error set of bench/experiments/make_ballbar_data.cpp (µm, µrad; s = (x - 250)/250).
  auto model_data = std::make_shared<ModelData>(*model);
  const DeviationFn f = [&](const double* q, double* out6) {
    const double y = q[0], x = q[1], s = (x - 250) / 250;
    std::vector<double> e(d.errors.size(), 0.0);
    auto set = [&](const char* name, double v) {
      const auto i = static_cast<std::size_t>(d.error_index(name));
      e[i] = v * d.errors[i].to_base;
    };
    set("E_XX", 1.5 * std::sin(2 * kPi * x / 125) + 0.008 * x);
    set("E_YY", 1.0 * std::cos(2 * kPi * y / 100) - 0.005 * y);
    set("E_XY", 1.2 * std::sin(2 * kPi * y / 400));
    set("E_YX", 2.0 * (1 - s * s));
    set("E_CX", 5.0 * s);
    set("E_CY", 3.0 * std::sin(2 * kPi * y / 400));
    set("E_C0Y", 12.0);
    model->deviation(*model_data, q, e.data(), out6);
  };
  const BallbarTrace predicted = predict_ballbar(m, c, f, 720);
  for (const BallbarTrace& measured : traces) {
    const BallbarComparison cmp = compare_ballbar(measured, predicted, c.radius_mm);
    // What remains is the set-up offset (3.0, -1.5), the bar length (-0.8) and noise σ = 0.2.
    // Standard errors: 0.2·sqrt(2/360) = 0.015 µm (offsets), 0.2/sqrt(360) = 0.011 µm (radius).
    CHECK(std::abs(cmp.difference.centre_offset_um[0] - 3.0) < 0.06);
    CHECK(std::abs(cmp.difference.centre_offset_um[1] + 1.5) < 0.06);
    CHECK(std::abs(cmp.difference.radius_deviation_um + 0.8) < 0.05);
    CHECK(cmp.centred.rms_um == doctest::Approx(std::sqrt(0.04 + 0.64)).epsilon(0.05));
    CHECK(cmp.centred.correlation > 0.98);
    CHECK(cmp.predicted.circular_deviation_um > 3);
    CHECK(std::abs(cmp.measured.circular_deviation_um - cmp.predicted.circular_deviation_um) < 1.0);
  }
  CHECK(circular_hysteresis_um(traces[0], traces[1]) < 1.5);  // noise only: no reversal
}
