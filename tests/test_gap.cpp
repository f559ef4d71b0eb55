// Gap diagnosis (weilgen/analysis/gap.hpp): each effect's fit on a small synthetic set, the
// false-positive rate on effect-free data, the held-out splits and bad data.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "test_support.hpp"
#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/analysis/gap.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;

namespace {

std::shared_ptr<const Model> vmc() { return test::builtin_model("vmc_3axis"); }

struct Row {
  double X, Y, Z, t_s, dir_X, cycle, T;
  double dir_Y = 0;  // ballbar traces: the direction of travel of Y
};

// Effect added to (dx, dy, dz) in µm at a row.
using EffectFn = std::function<std::array<double, 3>(const Row&)>;

PdgeBasisChoice poly2() {
  PdgeBasisChoice c;
  c.all = "poly:2";
  return c;
}

// vmc_3axis with random errors within their spreads (`scale` times; PDGEs in the basis
// `choice`, default poly:2): its first-order deviation (µm, µrad) and its errors (base units)
// at a pose, and N(0, 1) deviates for the noise from a separate stream.
class Truth {
 public:
  explicit Truth(std::uint32_t seed, PdgeBasisChoice choice = poly2(), double scale = 1)
      : choice_(std::move(choice)),
        param_(vmc()->description(), choice_),
        md_(*vmc()),
        noise_rng_(seed + 7919) {
    const Description& d = vmc()->description();
    std::mt19937 rng(seed);
    for (const IdentParameter& ip : param_.parameters())
      theta_.push_back(scale * d.errors[static_cast<std::size_t>(ip.error)].distribution.b *
                       n_(rng));
  }
  std::array<double, 6> deviation(const double* pose) {
    return predict_deviation(*vmc(), md_, param_, theta_, pose);
  }
  std::vector<double> errors(const double* pose) const {
    std::vector<double> e(vmc()->num_errors());
    param_.errors_at(pose, theta_.data(), e.data());
    return e;
  }
  double normal() { return n_(noise_rng_); }

 private:
  PdgeBasisChoice choice_;
  ErrorParameterisation param_;
  ModelData md_;
  std::vector<double> theta_;
  std::mt19937 noise_rng_;
  std::normal_distribution<double> n_{0, 1};
};

// Replaces the first-order deviation (µm) at a row, given the truth's errors there.
using TruthFn = std::function<std::array<double, 3>(const Row&, const std::vector<double>&)>;

// A grid of X, Y, Z visited in `cycles` cycles (X back and forth: dir_X), 60 s per pose, a
// spindle temperature rising 2 K with a 1 h lag; deviations from the machine's own model with
// random errors (poly:2), plus the effect and N(0, noise²).
std::string synth(std::uint32_t seed, const EffectFn& effect, double noise = 0.5, int cycles = 4,
                  int nx = 6, const TruthFn& truth = {}, const PdgeBasisChoice& choice = poly2(),
                  double error_scale = 1) {
  Truth truth_machine(seed, choice, error_scale);
  std::ostringstream s;
  s << "X,Y,Z,t_s,dir_X,cycle,T_spindle,dx_um,dy_um,dz_um\n";
  double t = 0;
  for (int cy = 1; cy <= cycles; ++cy)
    for (double Z : {-250.0, -150.0, -50.0})
      for (double Y : {-350.0, -200.0, -50.0})
        for (int k = 0; k < 2 * nx; ++k) {
          const bool up = k < nx;
          const int i = up ? k : 2 * nx - 1 - k;
          const double X = 500.0 * i / (nx - 1);
          const Row r{X,
                      Y,
                      Z,
                      t,
                      up ? 1.0 : -1.0,
                      static_cast<double>(cy),
                      22 + 2 * (1 - std::exp(-t / 3600))};
          const double q[3] = {Y, X, Z};
          std::array<double, 6> dev = truth_machine.deviation(q);
          if (truth) {
            const auto tr = truth(r, truth_machine.errors(q));
            for (int o = 0; o < 3; ++o)
              dev[static_cast<std::size_t>(o)] = tr[static_cast<std::size_t>(o)];
          }
          const std::array<double, 3> e = effect(r);
          s << X << "," << Y << "," << Z << "," << t << "," << r.dir_X << "," << cy << "," << r.T;
          for (int o = 0; o < 3; ++o)
            s << ","
              << dev[static_cast<std::size_t>(o)] + e[static_cast<std::size_t>(o)] +
                     noise * truth_machine.normal();
          s << "\n";
          t += 60;
        }
  return s.str();
}

GapResult diagnose(const std::string& csv, std::shared_ptr<const Model> model = vmc(),
                   const std::string& holdout = "cycle:4", const PdgeBasisChoice& c = poly2()) {
  const MeasurementTable t = parse_measurements(csv, "g.csv");
  const ErrorParameterisation p(model->description(), c, model->parameters());
  const GapData d = gap_data(t, model->description());
  return GapDiagnosis().run(*model, p, d, *parse_holdout(holdout), "test");
}

const EffectFit* effect(const GapResult& r, const std::string& name) {
  for (const EffectFit& e : r.explanation)
    if (e.name == name) return &e;
  return nullptr;
}

EffectFn none = [](const Row&) { return std::array<double, 3>{0, 0, 0}; };

}  // namespace

TEST_CASE("gap: reversal on X is named, with its size") {
  const GapResult r = diagnose(synth(1, [](const Row& w) {
    return std::array<double, 3>{2.0 * w.dir_X, 0, 0};  // B = 4 µm in dx
  }));
  CHECK(r.verdict.names("reversal"));
  const EffectFit* e = effect(r, "reversal");
  REQUIRE(e);
  CHECK(std::abs(e->params.at("reversal_um")) == doctest::Approx(4.0).epsilon(0.1));
  CHECK(e->heldout_rms_after_um < 1.2 * r.noise.sigma_um);
  CHECK(r.noise.sigma_um == doctest::Approx(0.5).epsilon(0.15));
}

TEST_CASE("gap: a periodic error along X: period and amplitude") {
  const GapResult r = diagnose(synth(
      2,
      [](const Row& w) {
        return std::array<double, 3>{0, 3.0 * std::sin(2 * M_PI * w.X / 125.0), 0};
      },
      0.5, 3, 21));
  CHECK(r.verdict.names("periodic"));
  const EffectFit* e = effect(r, "periodic");
  REQUIRE(e);
  CHECK(e->params.at("period_mm") == doctest::Approx(125).epsilon(0.05));
  CHECK(e->params.at("amplitude_um") == doctest::Approx(3.0).epsilon(0.15));
  // A shape of the straightness of X in y, through the kinematics.
  CHECK(e->params.count("error_E_YX") == 1);
  CHECK(e->summary.find("periodic E_YX of X: period 12") == 0);
  REQUIRE(e->region);
  CHECK(e->region->output == "dy");
}

TEST_CASE("gap: thermal drift with a lagged sensor") {
  const GapResult r = diagnose(synth(3, [](const Row& w) {
    return std::array<double, 3>{3.0 * (w.T - 22), 0, -1.0 * (w.T - 22)};
  }));
  CHECK(r.verdict.names("thermal_drift"));
  const EffectFit* e = effect(r, "thermal_drift");
  REQUIRE(e);
  CHECK(e->params.count("sensor_T_spindle") == 1);
  CHECK(e->params.at("drift_x_um_per_K") == doctest::Approx(3.0).epsilon(0.1));
  CHECK(e->params.at("drift_z_um_per_K") == doctest::Approx(-1.0).epsilon(0.1));
  // What remains is noise: no significant gap against σ²(1 + h). The held-out RMS after exceeds
  // the noise (0.5 µm) by the leverage of the heating cycle, whose temperatures the other
  // cycles do not span.
  CHECK(r.final.p_value >= 0.01);
  CHECK(r.final.rms_um < 1.4 * 0.5);
}

TEST_CASE("gap: a local bump along Y in dz is localised") {
  const GapResult r = diagnose(synth(
      4,
      [](const Row& w) {
        return std::array<double, 3>{0, 0, 4.0 * std::exp(-0.5 * std::pow((w.X - 300) / 40, 2))};
      },
      0.5, 3, 11));
  CHECK(r.verdict.names("pdge_shape"));
  const EffectFit* e = effect(r, "pdge_shape");
  REQUIRE(e);
  REQUIRE(e->region);
  CHECK(e->region->by == "X");
  CHECK(e->region->from <= 300);
  CHECK(e->region->to >= 300);
}

TEST_CASE("gap: an angular error the machine file leaves out is named") {
  // The model lacks E_AX (roll of X); the data come from the full machine with
  // E_AX(x) = 40 µrad · u², u = (2x − 500)/500. (A constant E_AX, or a missing squareness,
  // would be absorbed by E_AY's or E_CY's constant term: not a gap.)
  std::string yaml = test::read_text(test::machine_path("vmc_3axis"));
  const auto at = yaml.find("      E_AX:");
  REQUIRE(at != std::string::npos);
  yaml.erase(at, yaml.find('\n', at) - at + 1);
  const Description reduced = load_machine_text(yaml, "vmc_no_AX.yaml");
  auto model = std::make_shared<const Model>(reduced, 1, "numeric chain");
  const Model& full = *vmc();
  ModelData md(full);
  const int k = full.description().error_index("E_AX");
  const GapResult r =
      diagnose(synth(5, none, 0.5, 3, 6,
                     [&](const Row& w, const std::vector<double>&) {
                       std::vector<double> e(full.num_errors(), 0.0);
                       const double u = (2 * w.X - 500) / 500;
                       e[static_cast<std::size_t>(k)] = 40e-6 * u * u;
                       const double q[3] = {w.Y, w.X, w.Z};
                       std::array<double, 6> out{};
                       full.deviation(md, q, e.data(), out.data());
                       return std::array<double, 3>{out[0] * 1e3, out[1] * 1e3, out[2] * 1e3};
                     }),
               model);
  CHECK(r.verdict.names("missing_error"));
  const EffectFit* e = effect(r, "missing_error");
  REQUIRE(e);
  CHECK(e->variant == "E_AX");
  CHECK(e->params.at("E_AX_peak") == doctest::Approx(40).epsilon(0.15));
}

TEST_CASE("gap: no false positive on effect-free data (stated rate alpha = 0.01 per decision)") {
  int named = 0;
  const int seeds = 30;
  for (int s = 0; s < seeds; ++s) {
    const GapResult r = diagnose(synth(100 + static_cast<std::uint32_t>(s), none, 0.5, 3, 5));
    if (r.verdict.kind != GapVerdict::Kind::None) ++named;
  }
  // With alpha = 0.01 for the gap test, P(more than 2 of 30 flagged) < 0.004.
  CHECK(named <= 2);
}

TEST_CASE("gap: held-out splits never share an observation and cover every one once") {
  const MeasurementTable t = parse_measurements(synth(7, none), "g.csv");
  const GapData d = gap_data(t, vmc()->description());
  for (const char* scheme : {"cycle:4", "time:5", "space:X:3"}) {
    const std::vector<Split> splits = make_splits(d, *parse_holdout(scheme), 20);
    std::vector<int> held(d.points.observations.size(), 0);
    for (const Split& s : splits) {
      std::vector<bool> in_train(held.size(), false);
      for (std::size_t i : s.train) in_train[i] = true;
      for (std::size_t i : s.test) {
        CHECK_FALSE(in_train[i]);
        ++held[i];
      }
      CHECK(s.train.size() + s.test.size() == held.size());
    }
    for (int h : held) CHECK(h == 1);
  }
  // Cycle folds keep a cycle together.
  const std::vector<Split> by_cycle = make_splits(d, *parse_holdout("cycle:4"), 20);
  for (const Split& s : by_cycle) {
    std::set<double> cycles;
    for (std::size_t i : s.test) cycles.insert(d.cycle[d.points.observations[i].row]);
    CHECK(cycles.size() == 1);
  }
}

TEST_CASE("gap: bad data get a message, not a verdict") {
  const Description& desc = vmc()->description();
  auto error_of = [&](const std::string& csv, const std::string& holdout = "auto") {
    try {
      const MeasurementTable t = parse_measurements(csv, "b.csv");
      const GapData d = gap_data(t, desc);
      const auto h = parse_holdout(holdout);
      make_splits(d, h ? *h : default_holdout(d), 20);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of("X,Y,Z,t_s\n0,0,0,1\n") ==
        "b.csv:1: no deviation column (dx_um, dy_um, dz_um, da_urad, db_urad, dc_urad; "
        "columns: X, Y, Z, t_s)");
  std::string constant = "X,Y,Z,T_a,dx_um\n";
  for (int i = 0; i < 12; ++i) constant += std::to_string(i * 10) + ",0,0,21.5,1\n";
  CHECK(error_of(constant) ==
        "b.csv:1: column 'T_a' is constant (21.5 degC): it cannot explain anything; drop the "
        "column");
  std::string nan = "X,Y,Z,T_a,dx_um\n";
  for (int i = 0; i < 12; ++i)
    nan += std::to_string(i * 10) + ",0,0," + (i == 4 || i == 7 ? "" : "21." + std::to_string(i)) +
           ",1\n";
  CHECK(
      error_of(nan) ==
      "b.csv:6:8: column 'T_a' is empty in 2 rows where a deviation is measured (lines 6, 9): the "
      "diagnosis needs it in every row; fill or drop those rows");
  CHECK(error_of("X,Y,Z,dx_um\n0,0,0,1\n1,0,0,2\n") ==
        "b.csv: only 2 observations: the diagnosis needs at least 10");
  std::string few = "X,Y,Z,cycle,dx_um\n";
  for (int i = 0; i < 12; ++i)
    few += std::to_string(i * 10) + ",0,0," + (i < 11 ? "1" : "2") + ",1\n";
  CHECK(error_of(few, "cycle") ==
        "b.csv: --holdout cycle:5: too few observations: a training part has 1, the model needs at "
        "least 20");
  CHECK(error_of("Y,Z,dx_um\n0,0,1\n") ==
        "b.csv:1: missing column 'X' (give the coordinate of a pose the data do not vary with "
        "--at X=VALUE; columns: Y, Z, dx_um)");
  // A rotary coordinate in radians, a covariate with gaps: tests/test_gap_input.cpp.
  CHECK_THROWS_WITH_AS(parse_holdout("weekly"),
                       "--holdout \"weekly\": unknown scheme 'weekly' (expected cycle[:K], "
                       "time[:K], space[:AXIS][:K], forward[:FRACTION] or auto)",
                       std::invalid_argument);
}

TEST_CASE("gap CLI: JSON schema, report, and bad flags or data") {
  const std::filesystem::path dir = test::fresh_dir("gap_cli");
  const std::string data = (dir / "rev.csv").string();
  std::ofstream(data) << synth(9, [](const Row& w) {
    return std::array<double, 3>{1.5 * w.dir_X, 0, 0};
  });
  const std::string json = (dir / "gap.json").string(), md = (dir / "gap.md").string();
  const test::Run ok = test::run(test::cli("gap vmc_3axis -q --pdge poly:2 --data " + data +
                                           " --json " + json + " --report " + md));
  REQUIRE_MESSAGE(ok.status == 0, ok.out);
  CHECK(ok.out.find("Verdict: reversal") != std::string::npos);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["verdict"]["effect"] == "reversal");
  CHECK(j["verdict"]["explanation"][0] == "reversal");
  CHECK(j["baseline"]["holdout"] == "cycle:4");
  CHECK(j["noise_floor_source"] == "repeats");
  CHECK(j["noise_floor_um"].get<double>() == doctest::Approx(0.5).epsilon(0.2));
  REQUIRE(j["effects"].size() >= 5);
  for (const char* key : {"name", "params", "heldout_rms_before_um", "heldout_rms_after_um",
                          "shrink_pct", "significant", "p_value"})
    CHECK(j["effects"][0].contains(key));
  CHECK(j["effects"][0]["name"] == "reversal");
  CHECK(std::abs(j["effects"][0]["params"]["reversal_um"].get<double>()) ==
        doctest::Approx(3.0).epsilon(0.1));
  CHECK(j["where"][0]["output"] == "dx");
  CHECK(std::filesystem::exists(md));

  const test::Run bad1 =
      test::run(test::cli("gap vmc_3axis -q --data " + data + " --holdout weekly"));
  CHECK(bad1.status == 2);
  const test::Run bad2 =
      test::run(test::cli("gap vmc_3axis -q --data " + data + " --effects gremlins"));
  CHECK(bad2.status == 2);
  CHECK(bad2.out.find("unknown effect 'gremlins'") != std::string::npos);
  const std::string flat = (dir / "flat.csv").string();
  std::string text = "X,Y,Z,T_a,dx_um\n";
  for (int i = 0; i < 12; ++i) text += std::to_string(i * 10) + ",0,0,21.5,1\n";
  std::ofstream(flat) << text;
  const std::string never = (dir / "never.json").string();
  const test::Run bad3 =
      test::run(test::cli("gap vmc_3axis -q --data " + flat + " --json " + never));
  CHECK(bad3.status == 3);
  CHECK(bad3.out.find("flat.csv:1: column 'T_a' is constant") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(never));
}

TEST_CASE("gap: a step where the data cannot tell shapes apart is unexplained, not a shape") {
  // dx jumps by 6 µm at X = 250 mm. On 6 positions along X a quadratic PDGE basis leaves 3
  // shape degrees of freedom, and a period or a bump uses 3: either fits, neither is named.
  const EffectFn step = [](const Row& w) {
    return std::array<double, 3>{w.X >= 250 ? 6.0 : 0.0, 0, 0};
  };
  const GapResult coarse = diagnose(synth(11, step, 0.5, 3, 6));
  CHECK(coarse.verdict.kind == GapVerdict::Kind::Unexplained);
  REQUIRE_FALSE(coarse.explanation.empty());
  const EffectFit& first = coarse.explanation.front();
  CHECK_FALSE(first.distinguishable);
  CHECK(first.shape_dof_free == 3);
  CHECK(first.shape_dof_used >= 3);
  CHECK(coarse.verdict.reason.find("shape degrees of freedom along X") != std::string::npos);
  // On 21 positions the shapes are told apart, and none fits a step: still not a name.
  const GapResult fine = diagnose(synth(12, step, 0.5, 3, 21));
  CHECK(fine.verdict.kind == GapVerdict::Kind::Unexplained);
  CHECK(fine.baseline.p_value < 1e-6);
}

TEST_CASE("gap: a bump between the samples of a coarse grid is found and resolved") {
  // 11 positions along X (50 mm apart); the bump sits between two of them.
  const GapResult r = diagnose(synth(
      13,
      [](const Row& w) {
        return std::array<double, 3>{0, 5.0 * std::exp(-0.5 * std::pow((w.X - 262) / 50, 2)), 0};
      },
      0.5, 3, 11));
  CHECK(r.verdict.names("pdge_shape"));
  const EffectFit* e = effect(r, "pdge_shape");
  REQUIRE(e);
  CHECK(e->distinguishable);
  CHECK(e->params.at("centre_mm") == doctest::Approx(262).epsilon(0.03));
  CHECK(e->params.at("width_mm") == doctest::Approx(50).epsilon(0.15));
  CHECK(e->params.at("positions_covered") >= 3);
}

namespace {

// A ballbar trace of vmc_3axis in XY (centre X 250, Y -200, Z -150 mm; radius 100 mm), 2°
// steps, ccw then cw, `cycles` cycles; dr = exact projection of the model's deviation with
// random errors plus `extra` (µm, in dx dy dz), plus N(0, noise²).
std::string ballbar_synth(std::uint32_t seed, const EffectFn& extra, int cycles = 4,
                          double noise = 0.4, bool with_temperature = false,
                          bool dir_column = true) {
  Truth truth_machine(seed);
  const BallbarMachine bm = ballbar_machine(vmc()->description());
  BallbarFlags f;
  f.plane = "XY";
  f.centre = "X=250,Y=-200,Z=-150";
  f.radius = "100";
  const BallbarCircle circle = parse_ballbar_circle(f, bm);
  std::ostringstream s;
  s << "# plane: XY\n# centre: X=250, Y=-200, Z=-150\n# radius: 100 mm\n"
    << "t_s,dir," << (dir_column ? "dir_X," : "") << "cycle,angle_deg,"
    << (with_temperature ? "T_spindle," : "") << "dr_um\n";
  double t = 0;
  for (int cy = 1; cy <= cycles; ++cy)
    for (int feed : {1, -1})
      for (int k = 0; k < 180; ++k) {
        const double a = feed > 0 ? 2.0 * k : std::fmod(360 - 2.0 * k, 360.0);
        const std::vector<double> q = ballbar_pose(bm, circle, a);  // Y, X, Z
        const std::array<double, 3> u = ballbar_directions(bm, circle, {a}).front();
        // X moves toward +X on the way up when the feed's tangent has a positive x part.
        const double th = (a - feed * 1.0) * M_PI / 180;
        const double dir_x = -feed * std::sin(th) > 0 ? 1 : -1;
        const double dir_y = feed * std::cos(th) > 0 ? 1 : -1;
        // A spindle warming by 3 K with a time constant of a quarter of the run.
        const double temp = 22 + 3 * (1 - std::exp(-t / (cycles * 180.0 * 0.25)));
        const Row r{q[1], q[0], q[2], t, dir_x, static_cast<double>(cy), temp, dir_y};
        const std::array<double, 6> dev = truth_machine.deviation(q.data());
        const std::array<double, 3> e = extra(r);
        double dr = noise * truth_machine.normal();
        for (std::size_t o = 0; o < 3; ++o) dr += u[o] * (dev[o] + e[o]);
        s << t << "," << feed << ",";
        if (dir_column) s << dir_x << ",";
        s << cy << "," << a << ",";
        if (with_temperature) s << temp << ",";
        s << dr << "\n";
        t += 0.5;
      }
  return s.str();
}

}  // namespace

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

namespace {

// Deviation (µm) of the exact chain at a row's pose for given errors, with machine parameters
// changed from the model's by `changes` (name -> value, mm).
std::array<double, 3> exact_um(const Row& w, const std::vector<double>& errors,
                               const std::map<std::string, double>& changes = {}) {
  const Description& d = vmc()->description();
  NumericChain chain(d);
  std::vector<double> p = vmc()->parameters();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (changes.count(d.parameters[i].name)) p[i] = changes.at(d.parameters[i].name);
  chain.set_parameters(p);
  const std::array<double, 6> v = chain.deviation({w.Y, w.X, w.Z}, errors);
  return {v[0] * 1e3, v[1] * 1e3, v[2] * 1e3};
}

// Translation PDGEs linear, rotation PDGEs quadratic: then a tool length times a rotation is
// not a straightness the model already has.
PdgeBasisChoice linear_translations() {
  PdgeBasisChoice c = poly2();
  for (const char* e : {"E_XX", "E_YX", "E_ZX", "E_XY", "E_YY", "E_ZY", "E_XZ", "E_YZ", "E_ZZ"})
    c.per_error.emplace_back(e, "poly:1");
  return c;
}

}  // namespace

TEST_CASE("gap: products of errors (errors 200x their spreads) are higher_order, scale 1") {
  const GapResult r = diagnose(synth(
      31, none, 0.5, 3, 6,
      [](const Row& w, const std::vector<double>& e) { return exact_um(w, e); }, poly2(), 200));
  // Rotations of 2 mrad: products of errors reach µm, which a first-order model cannot fit.
  CHECK(r.verdict.names("higher_order"));
  const EffectFit* e = effect(r, "higher_order");
  REQUIRE(e);
  CHECK(e->params.at("scale") == doctest::Approx(1.0).epsilon(0.2));
}

TEST_CASE("gap: a tool 100 mm longer than the model's is fitted as a tool_offset of 100 mm") {
  const PdgeBasisChoice c = linear_translations();
  const GapResult r = diagnose(synth(
                                   32, none, 0.3, 3, 6,
                                   [](const Row& w, const std::vector<double>& e) {
                                     return exact_um(w, e, {{"tool_length", 100}});
                                   },
                                   c, 5),
                               vmc(), "cycle:3", c);
  // The tool column is the rotations' lever at the identified errors, which the first-order
  // data leave partly undetermined (rank-deficient model): the offset is recovered, and about
  // a fifth of the excess stays (the verdict then withholds the name).
  REQUIRE_FALSE(r.explanation.empty());
  const EffectFit& e = r.explanation.front();
  CHECK(e.name == "tool_offset");
  CHECK(e.params.at("offset_mm") == doctest::Approx(100).epsilon(0.05));
  CHECK(e.explained_fraction > 0.7);
}

TEST_CASE("gap: a cosine error of the measuring set-up along X is setup, with its size") {
  // dx reads 20 µm/m² · X² too much; its linear (scale) part is E_XX's own.
  const PdgeBasisChoice c = linear_translations();
  const GapResult r = diagnose(synth(
                                   33,
                                   [](const Row& w) {
                                     return std::array<double, 3>{20 * w.X * w.X / 1e6, 0, 0};
                                   },
                                   0.3, 3, 11, {}, c),
                               vmc(), "cycle:3", c);
  CHECK(r.verdict.names("setup"));
  const EffectFit* e = effect(r, "setup");
  REQUIRE(e);
  CHECK(e->variant == "dx along X");
  CHECK(e->params.at("quadratic_um_per_m2") == doctest::Approx(20).epsilon(0.1));
}

namespace {

// Adds `size_um` to the dx cell of `rows` data rows (1-based after the header) of a CSV.
std::string with_gross_readings(const std::string& csv, const std::vector<int>& rows,
                                double size_um) {
  std::istringstream in(csv);
  std::ostringstream out;
  std::string line;
  int n = -1;
  while (std::getline(in, line)) {
    if (n >= 0 && std::find(rows.begin(), rows.end(), n + 1) != rows.end()) {
      // dx_um is the 8th field.
      std::vector<std::string> f;
      std::stringstream ls(line);
      for (std::string cell; std::getline(ls, cell, ',');) f.push_back(cell);
      f[7] = std::to_string(std::stod(f[7]) + size_um);
      line.clear();
      for (std::size_t k = 0; k < f.size(); ++k) line += (k ? "," : "") + f[k];
    }
    out << line << "\n";
    ++n;
  }
  return out.str();
}

}  // namespace

TEST_CASE("gap: five gross readings are reported and removed, and the reversal is still named") {
  const std::string clean = synth(1, [](const Row& w) {
    return std::array<double, 3>{2.0 * w.dir_X, 0, 0};  // B = 4 µm in dx
  });
  const std::vector<int> rows = {17, 90, 151, 240, 333};
  const GapResult r = diagnose(with_gross_readings(clean, rows, 60));
  REQUIRE(r.outliers.size() == 5);
  for (std::size_t k = 0; k < 5; ++k) {
    CHECK(r.outliers[k].output == "dx");
    CHECK(r.outliers[k].line == rows[k] + 1);  // the header is line 1
    CHECK(r.outliers[k].residual_um == doctest::Approx(60).epsilon(0.1));
    CHECK(r.outliers[k].sigmas > 6);
  }
  CHECK(r.verdict.names("reversal"));
  const EffectFit* e = effect(r, "reversal");
  REQUIRE(e);
  CHECK(std::abs(e->params.at("reversal_um")) == doctest::Approx(4.0).epsilon(0.1));
  CHECK(std::isnan(r.residual_before[static_cast<std::size_t>(r.outliers[0].observation)]));
}

TEST_CASE("gap: gross readings the reversal masks are found against the model with it") {
  // B = 10 µm: the baseline's residual is ±5 µm, robust sigma about 7 µm, so 6 sigma is about
  // 44 µm and a 25 µm reading stays among them; against baseline and reversal (sigma 0.5 µm) it
  // lies 50 sigma out. Left in, the five fail the final gap test (unexplained).
  const std::string clean = synth(1, [](const Row& w) {
    return std::array<double, 3>{5.0 * w.dir_X, 0, 0};
  });
  const std::vector<int> big = {17, 240}, small = {90, 151, 333};
  const GapResult r = diagnose(with_gross_readings(with_gross_readings(clean, big, 60), small, 25));
  std::vector<int> lines;
  for (const GapOutlier& g : r.outliers) {
    CHECK(g.output == "dx");
    lines.push_back(g.line);
  }
  CHECK(lines == std::vector<int>{18, 91, 152, 241, 334});  // the header is line 1
  for (const GapOutlier& g : r.outliers)
    CHECK(std::abs(g.residual_um) ==
          doctest::Approx(g.line == 18 || g.line == 241 ? 60 : 25).epsilon(0.15));
  CHECK(r.verdict.names("reversal"));
  const EffectFit* e = effect(r, "reversal");
  REQUIRE(e);
  CHECK(std::abs(e->params.at("reversal_um")) == doctest::Approx(10.0).epsilon(0.05));
  for (const GapOutlier& g : r.outliers) {
    CHECK(std::isnan(r.residual_before[g.observation]));
    CHECK(std::isnan(r.residual_after[g.observation]));
  }
  // The reading kept beside them keeps its index: the residual vectors cover every observation.
  CHECK(r.residual_after.size() == r.observations + r.outliers.size());
}

TEST_CASE("gap: effect-free data with gross readings: outliers, and the verdict none") {
  int named = 0;
  for (std::uint32_t s = 0; s < 10; ++s) {
    const GapResult r =
        diagnose(with_gross_readings(synth(300 + s, none, 0.5, 3, 5), {5, 50, 95}, -40));
    CHECK(r.outliers.size() == 3);
    if (r.verdict.kind != GapVerdict::Kind::None) ++named;
  }
  CHECK(named <= 1);
}

TEST_CASE("gap: no significant held-out gap, no effect named") {
  // The baseline gap test decides: with effect-free data the verdict is none even when the
  // ranking's best candidate is (by chance) nominally significant, and the reason names it.
  for (std::uint32_t s = 0; s < 5; ++s) {
    const GapResult r = diagnose(synth(500 + s, none, 0.5, 3, 5));
    INFO("seed " << 500 + s << ": " << r.verdict.str() << ", " << r.verdict.reason);
    if (r.baseline.p_value >= 0.01) {
      CHECK(r.verdict.kind == GapVerdict::Kind::None);
      CHECK(r.explanation.empty());
      CHECK(r.verdict.reason.find("noise floor") != std::string::npos);
    }
  }
}

TEST_CASE("gap: a heat-up drift with a lag of 0.18 x the run is found under cycle folds") {
  // 432 rows 60 s apart: the run spans 25,860 s; the lag is 0.18 of it (4,655 s = 1.29 h). The
  // temperature column is dropped: the heat-up in time is what is tested (a sensor lagged behind
  // the synthetic spindle temperature can mimic it).
  const double span = 431 * 60.0, tau = 0.18 * span;
  std::string csv = synth(41, [tau](const Row& w) {
    return std::array<double, 3>{4 * (1 - std::exp(-w.t_s / tau)), 0,
                                 -3 * (1 - std::exp(-w.t_s / tau))};
  });
  std::istringstream in(csv);
  std::ostringstream out;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) f.push_back(cell);
    f.erase(f.begin() + 6);  // T_spindle
    for (std::size_t k = 0; k < f.size(); ++k) out << (k ? "," : "") << f[k];
    out << "\n";
  }
  const GapResult r = diagnose(out.str());
  CHECK(r.verdict.names("thermal_drift"));
  const EffectFit* e = effect(r, "thermal_drift");
  REQUIRE(e);
  INFO("variant: " << e->variant << ", summary: " << e->summary);
  REQUIRE(e->params.count("tau_h"));
  CHECK(e->params.at("tau_h") == doctest::Approx(tau / 3600).epsilon(0.1));
}

TEST_CASE(
    "gap: on a rotary table, a reversal of C is named through the kinematics, with its size") {
  // five_axis_ac: an R-test-like layout (the tool over points off the table's centre, A and C
  // turning), C approached alternately from both sides with 6.2 µrad of lost motion. The
  // deviation reaches dx and dy rotated by C: a constant per output cannot describe it.
  const auto model = test::builtin_model("five_axis_ac");
  const Description& desc = model->description();
  NumericChain chain(desc);
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0, 1);
  std::vector<double> errors(desc.errors.size());
  for (std::size_t i = 0; i < errors.size(); ++i)
    errors[i] = desc.errors[i].distribution.b * desc.errors[i].to_base * n01(rng);
  std::vector<std::string> names;
  for (int b : desc.axes())
    names.push_back(desc.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  const double B_urad = 6.2, B_deg = B_urad * 1e-6 * 180 / 3.14159265358979323846;
  std::ostringstream csv;
  for (const std::string& a : names) csv << a << ",";
  csv << "dir_C,cycle,t_s,dx_um,dy_um,dz_um\n";
  double t = 0;
  for (int cy = 1; cy <= 3; ++cy)
    for (double A : {-30.0, 0.0, 30.0})
      for (double xy : {60.0, 120.0})
        for (int k = 0; k < 16; ++k) {
          const bool up = k < 8;
          const double C = 45.0 * (up ? k : 15 - k);
          const double dir = up ? 1 : -1;
          std::vector<double> q;
          for (const std::string& a : names)
            q.push_back(a == "X" ? xy : a == "Y" ? -xy / 2 : a == "Z" ? -150 : a == "A" ? A : C);
          std::vector<double> actual = q;
          for (std::size_t a = 0; a < names.size(); ++a)
            if (names[a] == "C") actual[a] -= dir * B_deg / 2;
          const Eigen::Matrix4d real = chain.tool_in_workpiece(actual, errors);
          const Eigen::Matrix4d nominal =
              chain.tool_in_workpiece(q, std::vector<double>(errors.size(), 0.0));
          for (double v : q) csv << v << ",";
          csv << dir << "," << cy << "," << t;
          for (int o = 0; o < 3; ++o)
            csv << "," << 1000 * (real(o, 3) - nominal(o, 3)) + 0.3 * n01(rng);
          csv << "\n";
          t += 30;
        }
  const GapResult r = diagnose(csv.str(), model, "cycle:3", poly2());
  CHECK(r.verdict.names("reversal"));
  const EffectFit* e = effect(r, "reversal");
  REQUIRE(e);
  CHECK(e->summary.find("reversal of C") != std::string::npos);
  CHECK(std::abs(e->params.at("reversal_urad")) == doctest::Approx(B_urad).epsilon(0.1));
  REQUIRE_FALSE(r.where.empty());
  CHECK(r.where.front().by == "dir_C");
}

TEST_CASE("gap: on a tilting table, a spindle drift fixed in the machine frame is thermal_drift") {
  // five_axis_ac: the tool point drifts 8 µm along the machine's z with a heat-up lag; the
  // workpiece frame turns with A and C, so in dx dy dz the drift is R(A, C)^T (0, 0, 8) µm.
  const auto model = test::builtin_model("five_axis_ac");
  const Description& desc = model->description();
  NumericChain chain(desc);
  std::mt19937 rng(5);
  std::normal_distribution<double> n01(0, 1);
  std::vector<double> errors(desc.errors.size());
  for (std::size_t i = 0; i < errors.size(); ++i)
    errors[i] = desc.errors[i].distribution.b * desc.errors[i].to_base * n01(rng);
  std::vector<std::string> names;
  for (int b : desc.axes())
    names.push_back(desc.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  std::ostringstream csv;
  for (const std::string& a : names) csv << a << ",";
  csv << "cycle,t_s,dx_um,dy_um,dz_um\n";
  const double tau = 5000;
  double t = 0;
  for (int cy = 1; cy <= 3; ++cy)
    for (double A : {-60.0, -20.0, 20.0, 60.0})
      for (double C : {0.0, 60.0, 120.0, 180.0, 240.0, 300.0}) {
        std::vector<double> q;
        for (const std::string& a : names)
          q.push_back(a == "X" ? 50 : a == "Y" ? -40 : a == "Z" ? -150 : a == "A" ? A : C);
        const Eigen::Matrix3d r = chain.workpiece_in_base(q).block<3, 3>(0, 0);
        const Eigen::Vector3d drift =
            r.transpose() * Eigen::Vector3d(0, 0, 8 * (1 - std::exp(-t / tau)));
        const Eigen::Vector3d dev(chain.deviation(q, errors)[0], chain.deviation(q, errors)[1],
                                  chain.deviation(q, errors)[2]);
        for (double v : q) csv << v << ",";
        csv << cy << "," << t;
        for (int o = 0; o < 3; ++o) csv << "," << 1000 * dev[o] + drift[o] + 0.2 * n01(rng);
        csv << "\n";
        t += 200;
      }
  const GapResult r = diagnose(csv.str(), model, "cycle:3", poly2());
  CHECK(r.verdict.names("thermal_drift"));
  const EffectFit* e = effect(r, "thermal_drift");
  REQUIRE(e);
  INFO(e->summary);
  // On a table machine the tool's frame is the machine's: the tool-side growth is the drift.
  REQUIRE(e->params.count("drift_z_um"));
  CHECK(e->params.count("frame_tool") == 1);
  CHECK(std::abs(e->params.at("drift_z_um")) == doctest::Approx(8).epsilon(0.15));
  CHECK(std::abs(e->params.at("drift_x_um")) < 1);
}

namespace {

// Measurements of a shipped machine through its exact chain: random errors within the spreads
// (seed), each row's deviation = tool point at the actual axes and errors minus the nominal one
// (µm), plus N(0, noise²). `perturb` may change a row's actual axes, errors and add a tool-point
// displacement (µm, workpiece frame) from the row's pose, time and directions.
struct ChainRow {
  std::vector<double> q;              // commanded axes (Description::axes() order)
  std::map<std::string, double> dir;  // approach directions written as dir_<axis>
  double t_s = 0;
  int cycle = 1;
};
using Perturb = std::function<void(const ChainRow&, std::vector<double>& q_actual,
                                   std::vector<double>& errors, Eigen::Vector3d& extra_um)>;

std::string chain_csv(const Model& model, const std::vector<ChainRow>& rows, double noise,
                      std::uint32_t seed, const Perturb& perturb,
                      const std::string& extra_header = "",
                      const std::function<std::string(const ChainRow&)>& extra = {}) {
  const Description& desc = model.description();
  NumericChain chain(desc);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0, 1);
  std::vector<double> base(desc.errors.size());
  for (std::size_t i = 0; i < base.size(); ++i)
    base[i] = desc.errors[i].distribution.b * desc.errors[i].to_base * n01(rng);
  std::ostringstream csv;
  for (int b : desc.axes()) csv << desc.bodies[static_cast<std::size_t>(b)].joint.coordinate << ",";
  for (const auto& [a, d] : rows.front().dir) csv << "dir_" << a << ",";
  csv << "cycle,t_s" << extra_header << ",dx_um,dy_um,dz_um\n";
  const std::vector<double> zero(base.size(), 0.0);
  for (const ChainRow& r : rows) {
    std::vector<double> q = r.q, e = base;
    Eigen::Vector3d extra_um = Eigen::Vector3d::Zero();
    if (perturb) perturb(r, q, e, extra_um);
    const Eigen::Vector3d d = chain.tool_in_workpiece(q, e).block<3, 1>(0, 3) -
                              chain.tool_in_workpiece(r.q, zero).block<3, 1>(0, 3);
    for (double v : r.q) csv << v << ",";
    for (const auto& [a, v] : r.dir) csv << v << ",";
    csv << r.cycle << "," << r.t_s;
    if (extra) csv << "," << extra(r);
    for (int o = 0; o < 3; ++o) csv << "," << 1000 * d[o] + extra_um[o] + noise * n01(rng);
    csv << "\n";
  }
  return csv.str();
}

// vmc_3axis (axes Y, X, Z): X at 6 positions, Y at 11, Z at 2, X back and forth, 3 cycles, 60 s
// per pose.
std::vector<ChainRow> vmc_grid() {
  std::vector<ChainRow> rows;
  double t = 0;
  for (int cy = 1; cy <= 3; ++cy)
    for (double Z : {-250.0, -100.0})
      for (int j = 0; j < 11; ++j)
        for (int k = 0; k < 12; ++k) {
          const bool up = k < 6;
          const double X = 100.0 * (up ? k : 11 - k);
          const double Y = cy % 2 ? -400 + 40.0 * j : -40.0 * j;
          rows.push_back({{Y, X, Z}, {{"X", up ? 1.0 : -1.0}}, t, cy});
          t += 60;
        }
  return rows;
}

int error_index(const Model& m, const std::string& name) {
  const int k = m.description().error_index(name);
  REQUIRE(k >= 0);
  return k;
}

}  // namespace

TEST_CASE("gap: a bump of E_YY along Y is named with its error and recovered at its centre") {
  const auto model = vmc();
  const int k = error_index(*model, "E_YY");
  const double centre = -220, width = 45, height_um = 4;
  const std::string csv = chain_csv(
      *model, vmc_grid(), 0.3, 21,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
        const double z = (r.q[0] - centre) / width;
        e[static_cast<std::size_t>(k)] += height_um * 1e-3 * std::exp(-0.5 * z * z);
      });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  CHECK(r.verdict.names("pdge_shape"));
  const EffectFit* e = effect(r, "pdge_shape");
  REQUIRE(e);
  INFO(e->summary);
  CHECK(e->params.count("error_E_YY") == 1);
  CHECK(e->summary.find("bump of E_YY of Y") == 0);
  CHECK(e->params.at("centre_mm") == doctest::Approx(centre).epsilon(0.03));
  CHECK(std::abs(e->params.at("amplitude_um")) == doctest::Approx(height_um).epsilon(0.15));
  REQUIRE_FALSE(r.where.empty());
  CHECK(r.where.front().by == "Y");
  CHECK(r.where.front().from <= centre);
  CHECK(r.where.front().to >= centre);
}

TEST_CASE("gap: two effects at once, a reversal of X and a thermal drift, are both named") {
  const auto model = vmc();
  const int k = error_index(*model, "E_XX");
  auto T = [](double t) { return 22 + 2.5 * (1 - std::exp(-t / 4000)); };
  const std::string csv = chain_csv(
      *model, vmc_grid(), 0.3, 22,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d& x) {
        e[static_cast<std::size_t>(k)] += -r.dir.at("X") * 3e-3 / 2;  // B = 3 µm
        x = Eigen::Vector3d(0, 2.0, -1.5) * (T(r.t_s) - 22);          // µm/K in dy, dz
      },
      ",T_spindle", [&](const ChainRow& r) { return std::to_string(T(r.t_s)); });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  std::set<std::string> named;
  for (const EffectFit& f : r.explanation) named.insert(f.name);
  INFO(r.verdict.reason);
  CHECK((r.verdict.names("reversal") || r.verdict.names("thermal_drift")));
  CHECK(named == std::set<std::string>{"reversal", "thermal_drift"});
  const EffectFit* rev = effect(r, "reversal");
  REQUIRE(rev);
  CHECK(rev->summary.find("reversal of X") == 0);
  CHECK(std::abs(rev->params.at("reversal_um")) == doctest::Approx(3).epsilon(0.1));
  const EffectFit* th = effect(r, "thermal_drift");
  REQUIRE(th);
  INFO(th->summary);
  REQUIRE(th->params.count("drift_y_um_per_K"));
  CHECK(th->params.at("drift_y_um_per_K") == doctest::Approx(2.0).epsilon(0.1));
  // dz: the offset and Z's scale are nearly collinear over Z = -250, -100 mm; their sum at the
  // grid's mean Z is the growth.
  const double scale_z =
      th->params.count("scale_Z_um_per_m_per_K") ? th->params.at("scale_Z_um_per_m_per_K") : 0;
  CHECK(th->params.at("drift_z_um_per_K") - 0.175 * scale_z == doctest::Approx(-1.5).epsilon(0.1));
}

namespace {

// head_head_bc (axes Y, X, Z, C, B): the tool tip kept on a point of the table while B takes 5
// tilts and C 12 positions (up and down in turn), 3 cycles, 20 s per pose.
std::vector<ChainRow> head_rtest(const Model& model) {
  const Description& desc = model.description();
  NumericChain chain(desc);
  const std::vector<double> zero(desc.errors.size(), 0.0);
  const Eigen::Vector3d p(120, 80, -800);
  std::vector<ChainRow> rows;
  double t = 0;
  for (int cy = 1; cy <= 3; ++cy)
    for (int a = 0; a < 5; ++a)
      for (int c0 = 0; c0 < 12; ++c0) {
        const double B = -50 + 25.0 * a;
        const bool up = (a + cy) % 2 == 0;
        const double C = 30.0 * (up ? c0 : 11 - c0);
        std::vector<double> q = {0, 0, -250, C, B};  // Y X Z C B
        for (int it = 0; it < 4; ++it) {             // the linear axes onto p
          const Eigen::Vector3d f = chain.tool_in_workpiece(q, zero).block<3, 1>(0, 3) - p;
          // Y moves along y, X along x, Z along z, each +1 mm per mm.
          q[0] -= f[1], q[1] -= f[0], q[2] -= f[2];
        }
        rows.push_back({q, {{"C", up ? 1.0 : -1.0}}, t, cy});
        t += 20;
      }
  return rows;
}

}  // namespace

TEST_CASE("gap: on a head-head machine, a periodic error of the C head is named E_ZC of C") {
  const auto model = test::builtin_model("head_head_bc");
  const int k = error_index(*model, "E_ZC");
  const std::string csv = chain_csv(
      *model, head_rtest(*model), 0.3, 23,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
        e[static_cast<std::size_t>(k)] += 3e-3 * std::sin(2 * M_PI * r.q[3] / 120 + 0.4);
      });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  CHECK(r.verdict.names("periodic"));
  const EffectFit* e = effect(r, "periodic");
  REQUIRE(e);
  INFO(e->summary);
  CHECK(e->summary.find("periodic E_ZC of C") == 0);
  CHECK(e->params.at("period_deg") == doctest::Approx(120).epsilon(0.03));
  CHECK(e->params.at("amplitude_um") == doctest::Approx(3).epsilon(0.15));
}

TEST_CASE("gap: on a head-head machine, a ram growth is told from a spindle growth by its frame") {
  // The tool point moves 6 µm along the machine's z (the ram) with a heat-up lag; the spindle
  // turns with B and C, so a growth along the tool's axis would look different.
  const auto model = test::builtin_model("head_head_bc");
  const double tau = 3000;
  const std::string csv = chain_csv(
      *model, head_rtest(*model), 0.2, 24,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>&, Eigen::Vector3d& x) {
        x = Eigen::Vector3d(0, 0, 6 * (1 - std::exp(-r.t_s / tau)));
      });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  CHECK(r.verdict.names("thermal_drift"));
  const EffectFit* e = effect(r, "thermal_drift");
  REQUIRE(e);
  INFO(e->summary);
  CHECK(e->params.count("frame_machine") == 1);
  REQUIRE(e->params.count("drift_z_um"));
  CHECK(e->params.at("drift_z_um") == doctest::Approx(6).epsilon(0.15));
  CHECK(e->params.at("tau_h") == doctest::Approx(tau / 3600).epsilon(0.2));
}

TEST_CASE("gap: a basis term that vanishes at every sample is not fitted") {
  // As in identify (test_identify.cpp): sin(2π·2·y/L) is rounding noise at the five Y positions.
  // Each fold's equilibrated SVD used to count it in the rank (47) and fit it with ~1e16.
  const std::filesystem::path dir = test::fresh_dir("gap_vanishing_term");
  const std::string json = (dir / "g.json").string();
  const test::Run ok = test::run(test::cli("gap vmc_3axis -q --pdge E_YY=fourier:3 --data " +
                                           std::string(WEILGEN_SOURCE_DIR) +
                                           "/examples/data/vmc_3axis_points.csv --json " + json));
  REQUIRE_MESSAGE(ok.status == 0, ok.out);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["baseline"]["parameters"] == 78);
  CHECK(j["baseline"]["rank"] == 46);
  CHECK(j["baseline"]["heldout_rms_all_um"].get<double>() < 10);
}

TEST_CASE(
    "gap: a missing error of a rotary axis is fitted in its joint's --pdge basis (fourier:3)") {
  // The model lacks E_ZC (axial motion of the C head); the truth's E_ZC(C) has a third harmonic
  // (µm): 2 cos C + 1.5 sin 3C. Given fourier:3 for C's PDGEs, the candidate's shape is
  // fourier:3 like theirs; in the joint's default (fourier:2) it cannot follow the third
  // harmonic.
  const auto full = test::builtin_model("head_head_bc");
  std::string yaml = test::read_text(test::machine_path("head_head_bc"));
  const auto at = yaml.find("      E_ZC:");
  REQUIRE(at != std::string::npos);
  yaml.erase(at, yaml.find('\n', at) - at + 1);
  auto model =
      std::make_shared<const Model>(load_machine_text(yaml, "hh_no_ZC.yaml"), 1, "numeric chain");
  REQUIRE(model->description().error_index("E_ZC") < 0);
  const int k = error_index(*full, "E_ZC");
  const double noise = 0.2;
  const std::string csv = chain_csv(
      *full, head_rtest(*full), noise, 31,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
        const double c = r.q[3] * M_PI / 180;
        e[static_cast<std::size_t>(k)] = 1e-3 * (2 * std::cos(c) + 1.5 * std::sin(3 * c));
      });
  // --pdge poly:2, and fourier:3 for every PDGE of C (--pdge E_XC=fourier:3 ...).
  PdgeBasisChoice f3 = poly2();
  const Description& md = model->description();
  for (const ErrorDef& ed : md.errors)
    if (ed.dependence == Dependence::PDGE &&
        md.bodies[static_cast<std::size_t>(ed.body)].joint.coordinate == "C")
      f3.per_error.emplace_back(ed.name, "fourier:3");
  REQUIRE(f3.per_error.size() >= 3);
  const GapResult r = diagnose(csv, model, "cycle:3", f3);
  CHECK(r.verdict.names("missing_error"));
  const EffectFit* e = effect(r, "missing_error");
  REQUIRE(e);
  INFO(e->summary);
  CHECK(e->variant == "E_ZC");
  CHECK(e->summary.find("fourier:3") != std::string::npos);
  // Recovered in the data: a held-out gap many times the noise is brought to the noise.
  CHECK(r.baseline.rms_um > 5 * noise);
  CHECK(r.final.rms_um < 1.3 * noise);
  // Parts of the shape are nearly absorbed by the model's other errors here: their minimum-norm
  // joint coefficients are anything (the peak read 8.97e3 µm for a true 3.3 µm). Only the part
  // the data determine is reported, over the measured C, and says what it left out.
  double truth_peak = 0;
  for (int deg = 0; deg <= 330; ++deg) {
    const double c = deg * M_PI / 180;
    truth_peak = std::max(truth_peak, std::abs(2 * std::cos(c) + 1.5 * std::sin(3 * c)));
  }
  CHECK(e->terms == 7);
  CHECK(e->terms_absorbed >= 1);
  CHECK(e->terms_absorbed < e->terms);
  CHECK(e->summary.find("absorbed by the model's errors") != std::string::npos);
  REQUIRE(e->params.count("E_ZC_peak"));
  CHECK(e->params.at("E_ZC_peak") > 0.3 * truth_peak);
  CHECK(e->params.at("E_ZC_peak") < 1.5 * truth_peak);
  // The top where entry is the effect's own region, along C, in the output E_ZC moves most
  // (from the exact chain with E_ZC alone: the model cannot absorb an error it lacks).
  NumericChain chain(full->description());
  const std::vector<double> zero(full->num_errors(), 0.0);
  std::array<double, 3> ss{};
  for (const ChainRow& row : head_rtest(*full)) {
    std::vector<double> err = zero;
    const double c = row.q[3] * M_PI / 180;
    err[static_cast<std::size_t>(k)] = 1e-3 * (2 * std::cos(c) + 1.5 * std::sin(3 * c));
    const Eigen::Vector3d dv = chain.tool_in_workpiece(row.q, err).block<3, 1>(0, 3) -
                               chain.tool_in_workpiece(row.q, zero).block<3, 1>(0, 3);
    for (int o = 0; o < 3; ++o) ss[static_cast<std::size_t>(o)] += dv[o] * dv[o];
  }
  const char* names[3] = {"dx", "dy", "dz"};
  REQUIRE(!r.where.empty());
  CHECK(r.where.front().source == "effect");
  CHECK(r.where.front().by == "C");
  CHECK(r.where.front().output == names[std::max_element(ss.begin(), ss.end()) - ss.begin()]);
}

TEST_CASE("gap: effect-free data whose noise grows 4x across the layout are none") {
  // σ_i = s (1 + 3ρ_i), ρ_i the pose's distance from the first pose over the largest: one MAD
  // of all differences reads the floor 15 % low, and the held-out gap test flagged 5 of 10
  // such sets. The floor as the mean of per-region robust variances follows the spread.
  const auto model = vmc();
  const std::vector<ChainRow> rows = vmc_grid();
  const Eigen::Vector3d first(rows.front().q[0], rows.front().q[1], rows.front().q[2]);
  double far = 0;
  for (const ChainRow& r : rows)
    far = std::max(far, (Eigen::Vector3d(r.q[0], r.q[1], r.q[2]) - first).norm());
  int named = 0;
  double ratio = 0;
  const int seeds = 10;
  for (int s = 0; s < seeds; ++s) {
    std::mt19937 rng(900 + static_cast<std::uint32_t>(s));
    std::normal_distribution<double> n01(0, 1);
    double ss = 0;
    std::size_t n = 0;
    const std::string csv = chain_csv(
        *model, rows, 0, 200 + static_cast<std::uint32_t>(s),
        [&](const ChainRow& r, std::vector<double>&, std::vector<double>&, Eigen::Vector3d& x) {
          const double rho = (Eigen::Vector3d(r.q[0], r.q[1], r.q[2]) - first).norm() / far;
          const double sigma = 0.3 * (1 + 3 * rho);
          ss += 3 * sigma * sigma, n += 3;
          x = Eigen::Vector3d(sigma * n01(rng), sigma * n01(rng), sigma * n01(rng));
        });
    const GapResult r = diagnose(csv, model, "cycle:3");
    if (r.verdict.kind != GapVerdict::Kind::None) ++named;
    ratio += r.noise.sigma_um / std::sqrt(ss / static_cast<double>(n)) / seeds;
  }
  CHECK(named <= 1);
  // The floor reads the RMS of σ_i (0.99 over these seeds), not the median's 0.85 of it.
  CHECK(ratio == doctest::Approx(1).epsilon(0.04));
}

namespace {

// The first pass (cycle 1) of head_rtest: 60 poses, none repeated.
std::vector<ChainRow> head_rtest_one_pass(const Model& model) {
  std::vector<ChainRow> rows;
  for (const ChainRow& r : head_rtest(model))
    if (r.cycle == 1) rows.push_back(r);
  return rows;
}

PdgeBasisChoice poly(int degree) {
  PdgeBasisChoice c;
  c.all = "poly:" + std::to_string(degree);
  return c;
}

}  // namespace

TEST_CASE(
    "gap: on a small rotary set without repeats the floor reads the noise, and a step is seen") {
  // head_head_bc, one pass of 60 R-test poses (no pose repeated), time:5 folds, poly:3 PDGEs:
  // the held-out residual carries each fold's prediction error (held-out leverage up to several),
  // which neighbours in time far apart in B and C do not share. Taken as noise (Var(d) = 2σ²),
  // the floor read up to 2.8x σ on the benchmark's effect-free sets of this layout and steps
  // were `none`; with the differences' exact variance from the folds' factors it reads σ.
  const auto model = test::builtin_model("head_head_bc");
  const std::vector<ChainRow> rows = head_rtest_one_pass(*model);
  REQUIRE(rows.size() == 60);
  const PdgeBasisChoice poly3 = poly(3);
  const double noise = 0.5;
  for (std::uint32_t seed : {41u, 42u, 43u, 44u}) {
    const GapResult r = diagnose(chain_csv(*model, rows, noise, seed, {}), model, "time:5", poly3);
    INFO("seed " << seed << ": floor " << r.noise.sigma_um << " µm, " << r.noise.detail);
    CHECK(r.noise.source == "small-scale");
    CHECK(r.noise.sigma_um == doctest::Approx(noise).epsilon(0.25));
    // (The verdict on such sets: "effect-free small rotary sets are none when folds leave
    // directions undetermined".)
  }
  // A step of 4 µm in dz from the middle of the run on (outside the library).
  const std::string csv = chain_csv(
      *model, rows, noise, 45,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>&, Eigen::Vector3d& x) {
        x = Eigen::Vector3d(0, 0, r.t_s >= 30 * 20 ? 4.0 : 0.0);
      });
  const GapResult r = diagnose(csv, model, "time:5", poly3);
  INFO(r.verdict.reason);
  CHECK(r.noise.sigma_um < 1.25 * noise);
  // Seen: not `none`. (Which name it gets is the step's own problem, outside the library: the
  // model's errors absorb most of a step on 60 poses and thermal_drift fits the rest.)
  CHECK(r.verdict.kind != GapVerdict::Kind::None);
}

TEST_CASE(
    "gap: effect-free small rotary sets are none when folds leave directions undetermined, and a "
    "periodic error is still named") {
  // head_head_bc, 60 R-test poses, time:5 folds, poly:3 PDGEs (the benchmark's rtest_small): each
  // fold's held-out poses carry 3-5 directions of the errors that its training poses do not
  // determine. The minimum-norm fit predicts nothing along them, so the held-out residual holds
  // the true errors' part there, which no noise model contains; tested on all of it, some such
  // sets read `unexplained` (p down to 1e-7 in the benchmark). The test on the part each fold can
  // predict is at the floor.
  const auto model = test::builtin_model("head_head_bc");
  const std::vector<ChainRow> rows = head_rtest_one_pass(*model);
  REQUIRE(rows.size() == 60);
  const PdgeBasisChoice poly3 = poly(3);
  const double noise = 0.5;
  int flagged = 0;
  for (std::uint32_t seed = 60; seed < 72; ++seed) {
    const GapResult r = diagnose(chain_csv(*model, rows, noise, seed, {}), model, "time:5", poly3);
    INFO("seed " << seed << ": " << r.verdict.str() << ", " << r.verdict.reason);
    if (r.verdict.kind != GapVerdict::Kind::None) ++flagged;
  }
  CHECK(flagged == 0);  // 2 of these 12 on the test over all of the residual
  // The same layout with a periodic error of the C head (amplitude 2.5 µm, visible ~5x the noise).
  const int k = error_index(*model, "E_ZC");
  int named = 0;
  for (std::uint32_t seed = 60; seed < 64; ++seed) {
    const std::string csv = chain_csv(
        *model, rows, noise, seed,
        [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
          e[static_cast<std::size_t>(k)] += 2.5e-3 * std::sin(2 * M_PI * r.q[3] / 120 + 0.4);
        });
    const GapResult r = diagnose(csv, model, "time:5", poly3);
    INFO("seed " << seed << ": " << r.verdict.str() << ", " << r.verdict.reason);
    if (r.verdict.names("periodic")) ++named;
  }
  CHECK(named == 4);
}

namespace {

// head_head_bc, one pass of 60 R-test poses, time:5 folds, poly:3 PDGEs, noise 0.5 µm: a step of
// 4 µm (8x the noise) in dz from the middle of the run on (outside the library), seeds 45-50.
// Diagnosed once for the two tests that read it.
const std::vector<std::pair<std::uint32_t, GapResult>>& step_in_time_results() {
  static const std::vector<std::pair<std::uint32_t, GapResult>> results = [] {
    const auto model = test::builtin_model("head_head_bc");
    const std::vector<ChainRow> rows = head_rtest_one_pass(*model);
    REQUIRE(rows.size() == 60);
    std::vector<std::pair<std::uint32_t, GapResult>> out;
    for (std::uint32_t seed : {45u, 46u, 47u, 48u, 49u, 50u}) {
      const std::string csv = chain_csv(
          *model, rows, 0.5, seed,
          [&](const ChainRow& r, std::vector<double>&, std::vector<double>&, Eigen::Vector3d& x) {
            x = Eigen::Vector3d(0, 0, r.t_s >= 30 * 20 ? 4.0 : 0.0);
          });
      out.emplace_back(seed, diagnose(csv, model, "time:5", poly(3)));
    }
    return out;
  }();
  return results;
}

}  // namespace

TEST_CASE("gap: a step that an effect of the library only imitates is unexplained (lack of fit)") {
  // The step of step_in_time_results(): the model's errors absorb most of it and a thermal drift
  // in time, a set-up or a shape fits the rest, so a name was given; the lack-of-fit test after
  // acceptance (free offsets per output in bins of time and of every axis) finds the structure
  // the named effect leaves along time or an axis.
  int named = 0, seen = 0;
  for (const auto& seed_result : step_in_time_results()) {
    const auto& seed = seed_result.first;  // clang < 16 cannot capture a structured binding
    const auto& r = seed_result.second;
    INFO("seed " << seed << ": " << r.verdict.str() << ": " << r.verdict.reason);
    // (`none` is allowed here: the held-out gap alone can sit at the floor; the baseline's lack
    // of fit, tested below, is what sees the step then.)
    CHECK(!r.verdict.names("thermal_drift"));
    if (r.verdict.kind != GapVerdict::Kind::None && r.verdict.kind != GapVerdict::Kind::Unexplained)
      ++named;
    if (r.verdict.kind == GapVerdict::Kind::Unexplained) ++seen;
  }
  CHECK(named == 0);
  CHECK(seen >= 3);
}

TEST_CASE(
    "gap: products of errors with a part in the R-test's null space are higher_order, to the "
    "noise") {
  // head_head_bc on an R-test: the first-order model is rank-deficient, and errors 100x their
  // spreads have a null-space part the linear fit cannot see; its products with the rest can.
  // The one column at the minimum-norm errors leaves most of the products unexplained; the
  // exact chain refitted over all errors (Levenberg-Marquardt) fits them to the noise.
  const auto model = test::builtin_model("head_head_bc");
  const double noise = 0.3;
  const std::string csv = chain_csv(
      *model, head_rtest(*model), noise, 25,
      [](const ChainRow&, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
        for (double& v : e) v *= 100;
      });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  INFO(r.verdict.reason);
  CHECK(r.verdict.names("higher_order"));
  const EffectFit* e = effect(r, "higher_order");
  REQUIRE(e);
  CHECK(e->params.at("scale") == doctest::Approx(1.0).epsilon(0.05));
  for (int o = 0; o < 3; ++o) CHECK(r.final.rms[o] < 1.2 * noise);
}

TEST_CASE("gap: a step in time that the folds cannot predict is still seen (lack of fit)") {
  // The step of step_in_time_results(). Each fold's held-out poses lie mostly in directions its
  // training poses do not determine, which the held-out test leaves out, so its p can sit at the
  // floor; on all data the model cannot follow the step (lack of fit along time), so the gap is
  // significant, no candidate of the library removes it whole, and the verdict is unexplained.
  int unexplained = 0, heldout_blind = 0;
  for (const auto& seed_result : step_in_time_results()) {
    const auto& seed = seed_result.first;  // clang < 16 cannot capture a structured binding
    const auto& r = seed_result.second;
    INFO("seed " << seed << ": " << r.verdict.str() << ": " << r.verdict.reason << " (held-out p "
                 << r.baseline.p_value << ", lack of fit p " << r.baseline_lack_of_fit_p << ")");
    CHECK(r.baseline_lack_of_fit_p < 1e-6);
    CHECK(r.baseline_lack_of_fit_along == "time");
    if (r.verdict.kind == GapVerdict::Kind::Unexplained) ++unexplained;
    if (r.baseline.p_value >= 0.01) ++heldout_blind;
  }
  CHECK(unexplained == 6);
  CHECK(heldout_blind >= 2);  // the held-out test alone reads `none` there (p 0.064 and 0.021)
}

TEST_CASE(
    "gap: a thermal drift and a bump along C on a head-head R-test are both named (the search "
    "goes on while all data show a structure)") {
  // head_head_bc, 180 R-test poses, a spindle drift fixed in the machine frame plus a bump of
  // E_ZC along C (the benchmark's pdge_shape+thermal_drift on rtest). The drift is accepted
  // first; after it the held-out gap is at the floor, since the bump lies mostly in directions a
  // fold cannot predict from its training poses, while on all data the structure along C
  // stands out (lack of fit p < alpha^3). Stopping there named the drift alone, or called the
  // drift an imitation of a shape outside the library.
  const auto model = test::builtin_model("head_head_bc");
  const int k = error_index(*model, "E_ZC");
  auto T = [](double t) { return 22 + 2.5 * (1 - std::exp(-t / 1500)); };
  const double centre = 180, width = 30;
  const std::string csv = chain_csv(
      *model, head_rtest(*model), 1.0, 31,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d& x) {
        const double z = (r.q[3] - centre) / width;
        e[static_cast<std::size_t>(k)] += 30 * 1e-3 * std::exp(-0.5 * z * z);
        x = Eigen::Vector3d(-8, 4, 6) * (T(r.t_s) - 22);  // µm/K
      },
      ",T_spindle", [&](const ChainRow& r) { return std::to_string(T(r.t_s)); });
  const GapResult r = diagnose(csv, model, "cycle:3", poly(3));
  std::set<std::string> named;
  for (const EffectFit& f : r.explanation) named.insert(f.name);
  INFO(r.verdict << ": " << r.verdict.reason);
  CHECK((r.verdict.names("thermal_drift") || r.verdict.names("pdge_shape")));
  CHECK(named == std::set<std::string>{"pdge_shape", "thermal_drift"});
  const EffectFit* b = effect(r, "pdge_shape");
  REQUIRE(b);
  INFO(b->summary);
  CHECK(b->summary.find("bump of E_ZC of C") == 0);
  CHECK(b->params.at("centre_deg") == doctest::Approx(centre).epsilon(0.05));
}
