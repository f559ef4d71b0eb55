// Identification from the instruments' own files (weilgen/analysis/identify.hpp, docs/identify.md
// "Data"): ballbar traces whose set-up offsets the reference removes, 6D line files whose
// straightness lines and angular zeros it removes, and the three kinds mixed.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "test_support.hpp"
#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/analysis/identify.hpp"
#include "weilgen/measure/line6d.hpp"

using namespace weilgen;

namespace {

void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

// Truth parameters: each θ_p ~ N(0, σ_error) in declared units.
std::vector<double> random_theta(const Description& d, const ErrorParameterisation& p,
                                 std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  std::vector<double> t;
  for (const IdentParameter& ip : p.parameters())
    t.push_back(d.errors[static_cast<std::size_t>(ip.error)].distribution.b * n(rng));
  return t;
}

// A ballbar trace of `model` with parameters θ at 5° steps ccw: dr = u·d plus a set-up offset
// (a cos θ + b sin θ, µm) and N(0, noise²).
std::string trace(const Model& model, const ErrorParameterisation& param,
                  const std::vector<double>& theta, const std::string& plane,
                  const std::string& centre, double offset_a, double offset_b, double noise,
                  std::mt19937& rng) {
  const BallbarMachine bm = ballbar_machine(model);
  BallbarFlags f;
  f.plane = plane;
  f.centre = centre;
  f.radius = "100";
  const BallbarCircle circle = parse_ballbar_circle(f, bm);
  std::ostringstream s;
  s << "# machine: " << model.name() << "\n# plane: " << plane << "\n# centre: " << centre
    << "\n# radius: 100 mm\nangle_deg,dr_um\n";
  s.precision(17);
  ModelData md(model);
  std::normal_distribution<double> n(0, noise);
  for (int k = 0; k < 72; ++k) {
    const double a = 5.0 * k;
    const std::vector<double> q = ballbar_pose(bm, circle, a);
    const std::array<double, 3> u = ballbar_directions(bm, circle, {a}).front();
    const std::array<double, 6> d = predict_deviation(model, md, param, theta, q.data());
    const double t = a * M_PI / 180;
    double dr = offset_a * std::cos(t) + offset_b * std::sin(t) + (noise > 0 ? n(rng) : 0.0);
    for (std::size_t o = 0; o < 3; ++o) dr += u[o] * d[o];
    s << a << "," << dr << "\n";
  }
  return s.str();
}

}  // namespace

TEST_CASE("identify data: ballbar traces as data, the set-up's centre offset removed") {
  const auto model = test::builtin_model("vmc_3axis");
  const Description& d = model->description();
  const ErrorParameterisation param(d, {});
  std::mt19937 rng(5);
  const std::vector<double> truth = random_theta(d, param, rng);
  const auto dir = test::fresh_dir("identify_ballbar_data");
  const std::vector<std::pair<std::string, std::string>> circles = {
      {"XY", "X=250, Y=-200, Z=-150"}, {"XY", "X=150, Y=-120, Z=-250"},
      {"YZ", "X=250, Y=-200, Z=-150"}, {"ZX", "X=250, Y=-200, Z=-150"},
      {"ZX", "X=120, Y=-300, Z=-150"}, {"YZ", "X=380, Y=-120, Z=-150"}};
  std::vector<std::string> clean, offset;
  for (std::size_t c = 0; c < circles.size(); ++c) {
    const auto a = dir / ("clean" + std::to_string(c) + ".csv");
    const auto b = dir / ("offset" + std::to_string(c) + ".csv");
    write(a, trace(*model, param, truth, circles[c].first, circles[c].second, 0, 0, 0, rng));
    // A table ball placed 7 µm and -4 µm off the nominal centre.
    write(b,
          trace(*model, param, truth, circles[c].first, circles[c].second, 7.0 + c, -4.0, 0, rng));
    clean.push_back(a.string());
    offset.push_back(b.string());
  }
  const ReadOptions ro = machine_read_options(d, false);
  const PointData pc = merged_point_data(clean, d, ro, {}, {}, model->parameters());
  const PointData po = merged_point_data(offset, d, ro, {}, {}, model->parameters());
  CHECK(po.count[kRadialOutput] == 72 * circles.size());
  CHECK(po.references.size() == circles.size());
  const IdentifyResult rc = Identification().run(*model, param, pc);
  const IdentifyResult ro_ = Identification().run(*model, param, po);
  CHECK(rc.references == 2 * circles.size());
  CHECK(rc.rank == ro_.rank);
  CHECK(rc.rank > 10);
  // The offsets are set-up, not machine: both fits are the same, and they fit exactly.
  CHECK(ro_.residual_sigma < 1e-9);
  for (std::size_t p = 0; p < param.size(); ++p)
    CHECK(ro_.theta[p] == doctest::Approx(rc.theta[p]).scale(1).epsilon(1e-7));
  // Every identifiable parameter is the truth.
  for (std::size_t p = 0; p < param.size(); ++p)
    if (rc.identifiable[p]) CHECK(rc.theta[p] == doctest::Approx(truth[p]).scale(1).epsilon(1e-6));
  // Without the reference, the offsets would have been read as machine errors.
  PointData raw = po;
  raw.references.clear();
  const IdentifyResult rr = Identification().run(*model, param, raw);
  CHECK(rr.residual_sigma > 0.5);
}

TEST_CASE("identify data: a 6D line file observes its axis's errors modulo line and mean") {
  const auto model = test::builtin_model("vmc_3axis");
  const Description& d = model->description();
  const ErrorParameterisation param(d, {});
  std::mt19937 rng(9);
  const std::vector<double> truth = random_theta(d, param, rng);
  // Profiles of X's six errors in ISO spelling, with a beam line on the straightness and an
  // angular zero on the angles (as a real alignment leaves them).
  std::ostringstream s;
  s.precision(17);
  s << "# format: line6d\n# axis: X\n# machine: vmc_3axis\nX,cycle,E_XX_um,E_YX_um,E_ZX_um,"
       "E_AX_urad,E_BX_urad,E_CX_urad\n";
  std::vector<double> errors(d.errors.size()), pose = {-200, 0, -150};  // Y, X, Z
  const char* names[] = {"E_XX", "E_YX", "E_ZX", "E_AX", "E_BX", "E_CX"};
  for (int cycle = 1; cycle <= 2; ++cycle)
    for (int k = 0; k <= 20; ++k) {
      const double x = 25.0 * k;
      pose[1] = x;
      param.errors_at(pose.data(), truth.data(), errors.data());
      s << x << "," << cycle;
      for (int e = 0; e < 6; ++e) {
        const ErrorDef& err = d.errors[static_cast<std::size_t>(d.error_index(names[e]))];
        double v =
            error_measured_scale(err) * errors[static_cast<std::size_t>(d.error_index(names[e]))];
        if (e == 1 || e == 2) v += 3.0 - 0.01 * x;  // a misaligned beam
        if (e >= 3) v += 11.0 * e;                  // the head's angular zero
        s << "," << v;
      }
      s << "\n";
    }
  const auto dir = test::fresh_dir("identify_line6d_data");
  write(dir / "x.csv", s.str());
  const PointData data =
      merged_point_data({(dir / "x.csv").string()}, d, machine_read_options(d, false));
  CHECK(data.count[kLinePositioning] == 42);
  CHECK(data.count[kLineStraightness] == 84);
  CHECK(data.count[kLineAngular] == 126);
  CHECK(data.references.size() == 5);  // two lines, three means
  const IdentifyResult r = Identification().run(*model, param, data);
  CHECK(r.references == 2 * 2 + 3);
  // poly:3 on X: positioning 4 terms, straightness u² u³ (2 each), angles u u² u³ (3 each).
  CHECK(r.rank == 4 + 2 * 2 + 3 * 3);
  CHECK(r.residual_sigma < 1e-9);
  for (std::size_t p = 0; p < param.size(); ++p) {
    if (!r.identifiable[p]) continue;
    CHECK(r.theta[p] == doctest::Approx(truth[p]).scale(1).epsilon(1e-7));
    CHECK(d.errors[static_cast<std::size_t>(param.parameters()[p].error)].name.substr(3) == "X");
  }
}

TEST_CASE("identify data: bad 6D and ballbar files name file and line") {
  const auto model = test::builtin_model("two_axis");
  const Description& d = model->description();
  const auto dir = test::fresh_dir("identify_bad_instrument_data");
  write(dir / "z.csv", "# format: line6d\n# axis: Z\nZ,lin_um\n0,1\n10,2\n");
  try {
    merged_point_data({(dir / "z.csv").string()}, d, machine_read_options(d, false));
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) ==
          (dir / "z.csv").string() +
              ":2: line6d: axis 'Z' is not a linear axis of machine two_axis (its linear axes: Y)");
  }
  const auto vmc = test::builtin_model("vmc_3axis");
  write(dir / "b.csv",
        "# plane: XY\n# centre: X=250, Y=-200, Z=-150\n# radius: 100\nangle_deg\n0\n");
  try {
    merged_point_data({(dir / "b.csv").string()}, vmc->description(),
                      machine_read_options(vmc->description(), false));
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("b.csv:4: a ballbar trace needs a 'dr_um' column") !=
          std::string::npos);
  }
}
