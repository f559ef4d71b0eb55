// The gap diagnosis tests' shared generators (tests/gap/*.cpp): a vmc_3axis truth with random
// errors and its grid, ballbar and exact-chain measurement sets, the shipped machines' grid and
// R-test poses, five_axis_ac rows for the readers, gross readings, and the diagnosis of a CSV
// with the tests' defaults. One home for the data every topic file draws, as Pinocchio's
// unittest/utils/model-generator.hpp serves its tests.
#pragma once

#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/analysis/gap.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace weilgen::gap_test {

inline std::shared_ptr<const Model> vmc() { return test::builtin_model("vmc_3axis"); }

struct Row {
  double X, Y, Z, t_s, dir_X, cycle, T;
  double dir_Y = 0;  // ballbar traces: the direction of travel of Y
};

// Effect added to (dx, dy, dz) in µm at a row.
using EffectFn = std::function<std::array<double, 3>(const Row&)>;

inline PdgeBasisChoice poly2() {
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
inline std::string synth(std::uint32_t seed, const EffectFn& effect, double noise = 0.5,
                         int cycles = 4, int nx = 6, const TruthFn& truth = {},
                         const PdgeBasisChoice& choice = poly2(), double error_scale = 1) {
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

inline GapResult diagnose(const std::string& csv, std::shared_ptr<const Model> model = vmc(),
                          const std::string& holdout = "cycle:4",
                          const PdgeBasisChoice& c = poly2()) {
  const MeasurementTable t = parse_measurements(csv, "g.csv");
  const ErrorParameterisation p(model->description(), c, model->parameters());
  const GapData d = gap_data(t, model->description());
  return GapDiagnosis().run(*model, p, d, *parse_holdout(holdout), "test");
}

inline const EffectFit* effect(const GapResult& r, const std::string& name) {
  for (const EffectFit& e : r.explanation)
    if (e.name == name) return &e;
  return nullptr;
}

inline const EffectFn none = [](const Row&) { return std::array<double, 3>{0, 0, 0}; };

// A ballbar trace of vmc_3axis in XY (centre X 250, Y -200, Z -150 mm; radius 100 mm), 2°
// steps, ccw then cw, `cycles` cycles; dr = exact projection of the model's deviation with
// random errors plus `extra` (µm, in dx dy dz), plus N(0, noise²).
inline std::string ballbar_synth(std::uint32_t seed, const EffectFn& extra, int cycles = 4,
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

// Deviation (µm) of the exact chain at a row's pose for given errors, with machine parameters
// changed from the model's by `changes` (name -> value, mm).
inline std::array<double, 3> exact_um(const Row& w, const std::vector<double>& errors,
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
inline PdgeBasisChoice linear_translations() {
  PdgeBasisChoice c = poly2();
  for (const char* e : {"E_XX", "E_YX", "E_ZX", "E_XY", "E_YY", "E_ZY", "E_XZ", "E_YZ", "E_ZZ"})
    c.per_error.emplace_back(e, "poly:1");
  return c;
}

// Adds `size_um` to the dx cell of `rows` data rows (1-based after the header) of a CSV.
inline std::string with_gross_readings(const std::string& csv, const std::vector<int>& rows,
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

// Every error drawn at its machine-file scale, b N(0, 1), in base units (mm, rad), from `n01`
// over `rng` in the errors' order.
inline std::vector<double> file_scale_errors(const Description& desc, std::mt19937& rng,
                                             std::normal_distribution<double>& n01) {
  std::vector<double> errors(desc.errors.size());
  for (std::size_t i = 0; i < errors.size(); ++i)
    errors[i] = desc.errors[i].distribution.b * desc.errors[i].to_base * n01(rng);
  return errors;
}

inline std::string chain_csv(const Model& model, const std::vector<ChainRow>& rows, double noise,
                             std::uint32_t seed, const Perturb& perturb,
                             const std::string& extra_header = "",
                             const std::function<std::string(const ChainRow&)>& extra = {}) {
  const Description& desc = model.description();
  NumericChain chain(desc);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0, 1);
  const std::vector<double> base = file_scale_errors(desc, rng, n01);
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
inline std::vector<ChainRow> vmc_grid() {
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

inline int error_index(const Model& m, const std::string& name) {
  const int k = m.description().error_index(name);
  REQUIRE(k >= 0);
  return k;
}

// head_head_bc (axes Y, X, Z, C, B): the tool tip kept on a point of the table while B takes 5
// tilts and C 12 positions (up and down in turn), 3 cycles, 20 s per pose.
inline std::vector<ChainRow> head_rtest(const Model& model) {
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

// The first pass (cycle 1) of head_rtest: 60 poses, none repeated.
inline std::vector<ChainRow> head_rtest_one_pass(const Model& model) {
  std::vector<ChainRow> rows;
  for (const ChainRow& r : head_rtest(model))
    if (r.cycle == 1) rows.push_back(r);
  return rows;
}

inline PdgeBasisChoice poly(int degree) {
  PdgeBasisChoice c;
  c.all = "poly:" + std::to_string(degree);
  return c;
}

// five_axis_ac rows: X, Y, Z fixed, A over {-30, 0, 30} deg, C over `c` (written as given).
inline std::string five_axis_rows(const std::vector<std::string>& c) {
  std::string s = "X,Y,Z,A,C,t_s,dx_um,rpm\n";
  int t = 0;
  for (const char* a : {"-30", "0", "30"})
    for (const std::string& ci : c) {
      s += std::string("10,0,-100,") + a + "," + ci + "," + std::to_string(60 * t) + "," +
           std::to_string(0.1 * t) + "," + std::to_string(1000 + 10 * t) + "\n";
      ++t;
    }
  return s;
}

// As diagnose() above, on a shipped machine by name.
inline GapResult diagnose(const std::string& csv, const std::string& machine,
                          const std::string& holdout) {
  return diagnose(csv, test::builtin_model(machine), holdout);
}

}  // namespace weilgen::gap_test
