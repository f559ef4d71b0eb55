// The Sobol' study of the 70-error dual-chuck laser pipe cutter (machines/pipe_cutter.yaml; seed
// ../shared/seeds/lpcs_lie_group_sobol.txt, section 3): first-order (Saltelli) and total (Jansen)
// indices of dx, dy, dz and the pipe's roll da with bootstrap intervals, N = 20000 quasi-Monte
// Carlo samples, the Table 2 uniform error ranges, the jaws clamped at Y231 = Y451 = Z453 = 20 mm,
// the chucks at A04 = 0 (A12 follows A04) and the feeding carriage at X = 100, 450, 800 mm; at
// order 1 (built-in model) and order 2 (compiled at run time by the model loader), with the exact
// linear indices as a check; and, from the exact linear indices, what changes when the chucks
// turn (A04 = 0, 45, 90, 180 deg).
//
//   weilgen_exp_pipe_cutter_sobol [--out DIR] [--samples N] [--bootstrap R] [--threads T]
//                                 [--orders 1,2]
//
// Writes DIR/results.md (a Markdown fragment: essential errors per output, index sums, order-2
// minus order-1 differences, run summary), DIR/results.json (every index, timings, settings) and
// DIR/sobol_dx.png, sobol_dy.png, sobol_dz.png, sobol_da.png (first-order indices of the essential
// errors at the three poses, lowest requested order; skipped when gnuplot is missing).
//
// Links the built-in models (weilgen_builtin_models) and the generator (weilgen_generator, for
// the loader's run-time compilation of the order-2 model), besides weilgen_runtime.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"
#include "weilgen/report/plot.hpp"
#include "weilgen/uq/sobol_indices.hpp"

using namespace weilgen;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kEssential = 0.03;  // Jiang et al. 2021's threshold for an essential error
constexpr std::size_t kOutputs = 4;  // dx, dy, dz, da: outputs 0 .. 3 of Model::deviation
const char* const kOutputNames[kOutputs] = {"dx", "dy", "dz", "da"};
const char* const kOutputUnits[kOutputs] = {"mm", "mm", "mm", "rad"};
const double kTurnA04[] = {0, 45, 90, 180};  // deg, the chucks' angles of the turning table
constexpr std::size_t kTurns = 4;
const double kFeedX[] = {100, 450, 800};  // mm, Jiang et al. 2021's feeding positions
constexpr std::size_t kPoses = 3;

struct Options {
  std::string out = "docs/experiments/pipe_cutter";
  std::size_t samples = 20000, bootstrap = 200;
  unsigned threads = 0;
  std::vector<int> orders = {1, 2};
};

// One row of the turning table: exact linear figures at one X and A04.
struct TurnRow {
  double x = 0, a04 = 0;
  double sigma_radial_um = kNaN;                 // sqrt(var(dy) + var(dz)), µm
  double sigma_roll_urad = kNaN;                 // sqrt(var(da)), µrad
  double S_dy = kNaN, S_dz = kNaN, S_da = kNaN;  // of E_YY451, E_YY451 and E_AA04
};

// Per order, pose, output and error.
struct Entry {
  double S = kNaN, S_lo = kNaN, S_hi = kNaN, ST = kNaN, ST_lo = kNaN, ST_hi = kNaN;
  double S_exact = kNaN;
};

struct OutputStats {
  double mean = kNaN, variance = kNaN;
};

struct OrderRun {
  int order = 0;
  std::string origin, engine;
  double load_seconds = 0, sobol_seconds = 0;
  double pose_seconds[kPoses] = {0, 0, 0};
  std::size_t evaluations = 0;
  std::vector<Entry> entries;  // [pose][output][error]
  OutputStats stats[kPoses][kOutputs];
  std::size_t errors = 0;
  Entry& at(std::size_t p, std::size_t o, std::size_t i) {
    return entries[(p * kOutputs + o) * errors + i];
  }
  const Entry& at(std::size_t p, std::size_t o, std::size_t i) const {
    return entries[(p * kOutputs + o) * errors + i];
  }
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

[[noreturn]] void usage(const char* argv0, const std::string& why) {  // why empty: --help
  if (!why.empty()) std::fprintf(stderr, "%s: %s\n", argv0, why.c_str());
  std::fprintf(stderr,
               "usage: %s [--out DIR] [--samples N] [--bootstrap R] [--threads T] "
               "[--orders 1,2]\n",
               argv0);
  std::exit(why.empty() ? 0 : 2);
}

std::size_t parse_count(const char* argv0, const std::string& flag, const std::string& text,
                        std::size_t min) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || text[0] == '-' || v < min)
    usage(argv0, flag + ": expected an integer >= " + std::to_string(min) + ", not '" + text + "'");
  return static_cast<std::size_t>(v);
}

Options parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") usage(argv[0], "");
    if (i + 1 >= argc) usage(argv[0], "missing value after " + a);
    const std::string v = argv[++i];
    if (a == "--out") {
      o.out = v;
    } else if (a == "--samples") {
      o.samples = parse_count(argv[0], a, v, 2);
    } else if (a == "--bootstrap") {
      o.bootstrap = parse_count(argv[0], a, v, 0);
    } else if (a == "--threads") {
      o.threads = static_cast<unsigned>(parse_count(argv[0], a, v, 0));
    } else if (a == "--orders") {
      o.orders.clear();
      std::istringstream in(v);
      for (std::string item; std::getline(in, item, ',');) {
        const int r = static_cast<int>(parse_count(argv[0], a, item, 1));
        if (std::find(o.orders.begin(), o.orders.end(), r) != o.orders.end())
          usage(argv[0], "--orders: order " + item + " given twice");
        o.orders.push_back(r);
      }
      if (o.orders.empty()) usage(argv[0], "--orders: no order given");
      std::sort(o.orders.begin(), o.orders.end());
    } else {
      usage(argv[0], "unknown option " + a);
    }
  }
  return o;
}

// Jiang et al. 2021's poses, each in Description::axes() order, built by coordinate name.
std::vector<std::vector<double>> seed_poses(const Description& desc) {
  std::vector<std::vector<double>> poses;
  for (double x : kFeedX) {
    const std::map<std::string, double> by_name = {
        {"X", x}, {"Y231", 20}, {"A04", 0}, {"Y451", 20}, {"Z453", 20}};
    std::vector<double> pose;
    std::size_t used = 0;
    for (int b : desc.axes()) {
      const Joint& j = desc.bodies[b].joint;
      const auto it = by_name.find(j.coordinate);
      if (it == by_name.end())
        throw std::runtime_error("the pipe cutter has an axis " + j.coordinate +
                                 " that Jiang et al. 2021's poses do not set");
      if (j.max > j.min && (it->second < j.min || it->second > j.max))
        throw std::runtime_error("pose value " + j.coordinate + " = " + std::to_string(it->second) +
                                 " outside the axis range");
      pose.push_back(it->second);
      ++used;
    }
    if (used != by_name.size())
      throw std::runtime_error("the pipe cutter lacks an axis of Jiang et al. 2021's poses");
    poses.push_back(pose);
  }
  return poses;
}

GeneratedHeader generate_for_loader(const Description& d, int order) {
  GeneratedHeader h;
  h.text = gen::generate_header(d, order, &h.name_space);
  return h;
}

// ---- Formatting ----------------------------------------------------------------------------

// Three decimals; "-0.000" prints as "0.000".
std::string f3(double v) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  std::string s = buf;
  if (s == "-0.000") s = "0.000";
  return s;
}

// Three significant digits, no exponent (positions, times, rates).
std::string g3(double v) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, std::abs(v) >= 100 ? "%.0f" : "%.3g", v);
  return buf;
}

// Three significant digits with an exponent (small differences).
std::string e3(double v) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2e", v);
  return buf;
}

// A duration: ms below 1 s, else s.
std::string duration(double seconds) {
  return seconds < 1 ? g3(1e3 * seconds) + " ms" : g3(seconds) + " s";
}

std::string with_ci(const Entry& e) {
  if (!std::isfinite(e.S_lo)) return f3(e.S);
  return f3(e.S) + " [" + f3(e.S_lo) + ", " + f3(e.S_hi) + "]";
}

std::string first_alias(const ErrorDef& e) {
  if (e.aliases.empty()) return "";
  return (e.aliases[0].sign < 0 ? "−" : "") + e.aliases[0].name;
}

std::string x_label(std::size_t p) { return "X = " + g3(kFeedX[p]) + " mm"; }

nlohmann::json json_number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// Errors with S > kEssential at any pose, sorted by S at the last pose (X = 800) descending.
std::vector<std::size_t> essential_errors(const OrderRun& run, std::size_t o) {
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < run.errors; ++i) {
    bool essential = false;
    for (std::size_t p = 0; p < kPoses; ++p)
      essential = essential || run.at(p, o, i).S > kEssential;
    if (essential) rows.push_back(i);
  }
  std::stable_sort(rows.begin(), rows.end(), [&](std::size_t a, std::size_t b) {
    return run.at(kPoses - 1, o, a).S > run.at(kPoses - 1, o, b).S;
  });
  return rows;
}

// Exact linear figures of the model's first-order part at every X and every A04 of kTurnA04:
// the radial and roll spreads and the indices that show the main chuck's jaws turning with it.
std::vector<TurnRow> turning_table(const Model& model, const Description& desc,
                                   const std::vector<std::vector<double>>& poses,
                                   const std::vector<InputDistribution>& inputs) {
  const std::size_t ne = desc.errors.size();
  const auto yy451 = static_cast<std::size_t>(desc.error_index("E_YY451"));
  const auto aa04 = static_cast<std::size_t>(desc.error_index("E_AA04"));
  std::size_t a04_axis = 0;
  const std::vector<int> axes = desc.axes();
  for (std::size_t a = 0; a < axes.size(); ++a)
    if (desc.bodies[static_cast<std::size_t>(axes[a])].joint.coordinate == "A04") a04_axis = a;
  ModelData data(model);
  std::vector<TurnRow> rows;
  for (std::size_t p = 0; p < kPoses; ++p)
    for (double a04 : kTurnA04) {
      std::vector<double> pose = poses[p];
      pose[a04_axis] = a04;
      model.coefficients(data, pose.data(), data.coeff.data());
      const auto column = [&](std::size_t o) {
        return std::vector<double>(data.coeff.begin() + static_cast<long>(o * ne),
                                   data.coeff.begin() + static_cast<long>((o + 1) * ne));
      };
      double radial = 0, roll = 0;
      for (std::size_t i = 0; i < ne; ++i) {
        const double var = inputs[i].stddev() * inputs[i].stddev();
        radial += var * (data.coeff[ne + i] * data.coeff[ne + i] +
                         data.coeff[2 * ne + i] * data.coeff[2 * ne + i]);
        roll += var * data.coeff[3 * ne + i] * data.coeff[3 * ne + i];
      }
      TurnRow r;
      r.x = kFeedX[p];
      r.a04 = a04;
      r.sigma_radial_um = 1e3 * std::sqrt(radial);
      r.sigma_roll_urad = 1e6 * std::sqrt(roll);
      r.S_dy = linear_sobol_indices(column(1), inputs)[yy451];
      r.S_dz = linear_sobol_indices(column(2), inputs)[yy451];
      r.S_da = linear_sobol_indices(column(3), inputs)[aa04];
      rows.push_back(r);
    }
  return rows;
}

std::string results_markdown(const Description& desc, const std::vector<OrderRun>& runs,
                             const std::vector<TurnRow>& turns, const Options& opt,
                             unsigned threads, double design_seconds, double confidence) {
  std::ostringstream md;
  const auto& errors = desc.errors;
  const int ci = static_cast<int>(std::lround(100 * confidence));
  md << "<!-- Written by weilgen_exp_pipe_cutter_sobol (bench/experiments/pipe_cutter_sobol.cpp)."
        " -->\n\n";
  md << "Sobol' indices of the working point's deviation (dx, dy, dz) and the pipe's roll (da) of `"
     << desc.name << "` (" << errors.size() << " errors, uniform per Table 2), N = " << opt.samples
     << " quasi-Monte Carlo samples (Sobol' points, digital shift seed 1), " << ci
     << " % bootstrap intervals (" << opt.bootstrap
     << " resamples); poses Y231 = 20, A04 = 0 (A12 = A04), Y451 = 20, Z453 = 20 and X = 100, 450, "
        "800 mm.\n";

  // (a) essential errors per order and output.
  for (const OrderRun& run : runs) {
    const bool exact = run.order == 1;
    for (std::size_t o = 0; o < kOutputs; ++o) {
      const std::vector<std::size_t> rows = essential_errors(run, o);
      md << "\n### " << kOutputNames[o] << ": essential errors (S > " << kEssential
         << " at any X), order " << run.order << "\n\n";
      if (rows.empty()) {
        md << "No error has S > " << kEssential << ".\n";
        continue;
      }
      md << "| error | alias | group |";
      for (std::size_t p = 0; p < kPoses; ++p) {
        md << " S [CI], " << x_label(p) << " | S_T, " << x_label(p) << " |";
        if (exact) md << " S exact, " << x_label(p) << " |";
      }
      md << "\n| --- | --- | --- |";
      for (std::size_t p = 0; p < kPoses; ++p)
        md << (exact ? " ---: | ---: | ---: |" : " ---: | ---: |");
      md << "\n";
      for (std::size_t i : rows) {
        md << "| `" << errors[i].name << "` | " << first_alias(errors[i]) << " | "
           << errors[i].group << " |";
        for (std::size_t p = 0; p < kPoses; ++p) {
          const Entry& e = run.at(p, o, i);
          md << " " << with_ci(e) << " | " << f3(e.ST) << " |";
          if (exact) md << " " << f3(e.S_exact) << " |";
        }
        md << "\n";
      }
    }
  }

  // (b) sums.
  md << "\n### Sum of S_i and of S_Ti\n\n| output | X (mm) |";
  for (const OrderRun& run : runs)
    md << " Σ S_i, order " << run.order << " | Σ S_Ti, order " << run.order << " |";
  md << "\n| --- | ---: |";
  for (std::size_t k = 0; k < runs.size(); ++k) md << " ---: | ---: |";
  md << "\n";
  for (std::size_t o = 0; o < kOutputs; ++o)
    for (std::size_t p = 0; p < kPoses; ++p) {
      md << "| " << kOutputNames[o] << " | " << g3(kFeedX[p]) << " |";
      for (const OrderRun& run : runs) {
        double s = 0, st = 0;
        for (std::size_t i = 0; i < run.errors; ++i) {
          s += run.at(p, o, i).S;
          st += run.at(p, o, i).ST;
        }
        md << " " << f3(s) << " | " << f3(st) << " |";
      }
      md << "\n";
    }

  // (c) order 2 against order 1.
  const OrderRun* r1 = nullptr;
  const OrderRun* r2 = nullptr;
  for (const OrderRun& run : runs) {
    if (run.order == 1) r1 = &run;
    if (run.order == 2) r2 = &run;
  }
  if (r1 && r2) {
    md << "\n### Order 2 against order 1: largest |S(2) − S(1)| and |S_T(2) − S_T(1)|\n\n"
       << "Same design (points and bootstrap resamples) at both orders.\n\n"
       << "| output | X (mm) | max abs(ΔS) | error | max abs(ΔS_T) | error |\n"
       << "| --- | ---: | ---: | --- | ---: | --- |\n";
    for (std::size_t o = 0; o < kOutputs; ++o)
      for (std::size_t p = 0; p < kPoses; ++p) {
        double ds = -1, dt = -1;
        std::size_t is = 0, it = 0;
        for (std::size_t i = 0; i < r1->errors; ++i) {
          const double a = std::abs(r2->at(p, o, i).S - r1->at(p, o, i).S);
          const double b = std::abs(r2->at(p, o, i).ST - r1->at(p, o, i).ST);
          if (a > ds) ds = a, is = i;
          if (b > dt) dt = b, it = i;
        }
        md << "| " << kOutputNames[o] << " | " << g3(kFeedX[p]) << " | " << e3(ds) << " | `"
           << errors[is].name << "` | " << e3(dt) << " | `" << errors[it].name << "` |\n";
      }
  }

  // (d) turning the chucks.
  md << "\n### Turning the chucks (exact linear indices)\n\n"
     << "σ_radial = √(var(dy) + var(dz)) of the working point, σ(da) of the roll; S of E_YY451 "
        "(jaw 45.1's positioning) in dy and dz, of E_AA04 (the main DD motor's angular "
        "positioning) in da.\n\n"
     << "| X (mm) | A04 (deg) | σ_radial (µm) | σ(da) (µrad) | S(E_YY451) dy | S(E_YY451) dz | "
        "S(E_AA04) da |\n| ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const TurnRow& r : turns)
    md << "| " << g3(r.x) << " | " << g3(r.a04) << " | " << f3(r.sigma_radial_um) << " | "
       << f3(r.sigma_roll_urad) << " | " << f3(r.S_dy) << " | " << f3(r.S_dz) << " | " << f3(r.S_da)
       << " |\n";

  // (e) run summary.
  md << "\n### Run summary\n\n| | value |\n| --- | --- |\n"
     << "| base sample size N | " << opt.samples << " |\n"
     << "| bootstrap resamples | " << opt.bootstrap << " |\n"
     << "| threads | " << threads << " |\n"
     << "| design (A, B, resamples) | " << duration(design_seconds) << " |\n";
  for (const OrderRun& run : runs)
    md << "| order " << run.order << ": model | " << run.origin << " (loaded in "
       << duration(run.load_seconds) << ") |\n"
       << "| order " << run.order << ": evaluations | " << run.evaluations << " (" << kPoses
       << " poses × N × (k + 2), k = " << run.evaluations / (kPoses * opt.samples) - 2
       << " sampled errors) |\n"
       << "| order " << run.order << ": Sobol' wall time | " << duration(run.sobol_seconds) << " ("
       << g3(1e9 * run.sobol_seconds / static_cast<double>(run.evaluations))
       << " ns per evaluation, bootstrap included) |\n";
  return md.str();
}

nlohmann::json results_json(const Description& desc, const std::vector<InputDistribution>& inputs,
                            const std::vector<std::vector<double>>& poses,
                            const std::vector<OrderRun>& runs, const std::vector<TurnRow>& turns,
                            const Options& opt, unsigned threads, double design_seconds,
                            double confidence) {
  const auto& errors = desc.errors;
  nlohmann::json axes = nlohmann::json::array();
  for (int b : desc.axes()) axes.push_back(desc.bodies[b].joint.coordinate);
  const auto pose_json = [&](std::size_t p) {
    nlohmann::json j = nlohmann::json::object();
    for (std::size_t a = 0; a < axes.size(); ++a) j[axes[a].get<std::string>()] = poses[p][a];
    return j;
  };
  nlohmann::json pose_list = nlohmann::json::array();
  for (std::size_t p = 0; p < kPoses; ++p) pose_list.push_back(pose_json(p));
  nlohmann::json in = nlohmann::json::array();
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const InputDistribution d = inputs[i].scaled(1.0 / errors[i].to_base);
    in.push_back({{"error", errors[i].name},
                  {"alias", first_alias(errors[i])},
                  {"group", errors[i].group},
                  {"unit", errors[i].unit},
                  {"distribution", d.str()}});
  }
  nlohmann::json timings = nlohmann::json::object(), runs_json = nlohmann::json::array();
  timings["design_seconds"] = design_seconds;
  nlohmann::json results = nlohmann::json::array(), summary = nlohmann::json::array();
  for (const OrderRun& run : runs) {
    nlohmann::json per_pose = nlohmann::json::array();
    for (std::size_t p = 0; p < kPoses; ++p) per_pose.push_back(run.pose_seconds[p]);
    runs_json.push_back({{"order", run.order},
                         {"engine", run.engine},
                         {"origin", run.origin},
                         {"load_seconds", run.load_seconds},
                         {"sobol_seconds", run.sobol_seconds},
                         {"sobol_seconds_per_pose", per_pose},
                         {"evaluations", run.evaluations}});
    for (std::size_t p = 0; p < kPoses; ++p)
      for (std::size_t o = 0; o < kOutputs; ++o) {
        summary.push_back({{"order", run.order},
                           {"pose", pose_json(p)},
                           {"output", kOutputNames[o]},
                           {"unit", kOutputUnits[o]},
                           {"mean", json_number(run.stats[p][o].mean)},
                           {"variance", json_number(run.stats[p][o].variance)}});
        for (std::size_t i = 0; i < run.errors; ++i) {
          const Entry& e = run.at(p, o, i);
          results.push_back({{"order", run.order},
                             {"pose", pose_json(p)},
                             {"output", kOutputNames[o]},
                             {"error", errors[i].name},
                             {"S", json_number(e.S)},
                             {"S_lo", json_number(e.S_lo)},
                             {"S_hi", json_number(e.S_hi)},
                             {"ST", json_number(e.ST)},
                             {"ST_lo", json_number(e.ST_lo)},
                             {"ST_hi", json_number(e.ST_hi)},
                             {"S_exact", json_number(e.S_exact)}});
        }
      }
  }
  timings["runs"] = runs_json;
  nlohmann::json turning = nlohmann::json::array();
  for (const TurnRow& r : turns)
    turning.push_back({{"X_mm", r.x},
                       {"A04_deg", r.a04},
                       {"sigma_radial_um", r.sigma_radial_um},
                       {"sigma_da_urad", r.sigma_roll_urad},
                       {"S_dy_E_YY451", r.S_dy},
                       {"S_dz_E_YY451", r.S_dz},
                       {"S_da_E_AA04", r.S_da}});
  return {{"weilgen", kVersion},
          {"experiment", "pipe_cutter_sobol"},
          {"machine", {{"name", desc.name}, {"source", desc.source_file}, {"axes", axes}}},
          {"settings",
           {{"samples", opt.samples},
            {"sampling", "qmc"},
            {"seed", 1},
            {"bootstrap", opt.bootstrap},
            {"confidence", confidence},
            {"threads", threads},
            {"orders", opt.orders},
            {"outputs", {"dx", "dy", "dz", "da"}},
            {"essential_threshold", kEssential},
            {"poses", pose_list}}},
          {"inputs", in},
          {"timings", timings},
          {"summary", summary},
          {"turning", turning},
          {"results", results}};
}

void write_charts(const Description& desc, const OrderRun& run, const Options& opt,
                  std::vector<std::string>& written) {
  if (!gnuplot_available()) {
    std::cout << "gnuplot not found on PATH: bar charts skipped (install gnuplot-nox)\n";
    return;
  }
  for (std::size_t o = 0; o < kOutputs; ++o) {
    const std::vector<std::size_t> rows = essential_errors(run, o);
    if (rows.empty()) {
      std::cout << "no essential error for " << kOutputNames[o] << ": chart skipped\n";
      continue;
    }
    BarChart chart;
    chart.title = std::string("pipe cutter: first-order Sobol' indices of ") + kOutputNames[o] +
                  " (order " + std::to_string(run.order) + ", N = " + std::to_string(opt.samples) +
                  ")";
    chart.ylabel = "S_i";
    for (std::size_t i : rows) chart.categories.push_back(desc.errors[i].name);
    for (std::size_t p = 0; p < kPoses; ++p) {
      BarSeries s{x_label(p), {}, {}, {}};
      bool intervals = opt.bootstrap > 0;
      for (std::size_t i : rows) {
        const Entry& e = run.at(p, o, i);
        s.value.push_back(e.S);
        s.lo.push_back(e.S_lo);
        s.hi.push_back(e.S_hi);
        intervals = intervals && std::isfinite(e.S_lo) && std::isfinite(e.S_hi);
      }
      if (!intervals) s.lo.clear(), s.hi.clear();
      chart.series.push_back(s);
    }
    const std::string path =
        (std::filesystem::path(opt.out) / (std::string("sobol_") + kOutputNames[o] + ".png"))
            .string();
    write_plot(path, {chart}, "");
    written.push_back(path);
  }
}

int run(const Options& opt) {
  const auto start = std::chrono::steady_clock::now();
  const unsigned threads = resolve_threads(opt.threads);
  const Description desc = load_machine_file(resolve_machine("pipe_cutter"));
  const std::vector<InputDistribution> inputs = error_distributions(desc, {}, {});
  const std::vector<std::vector<double>> poses = seed_poses(desc);
  const std::size_t ne = desc.errors.size();
  std::cout << "pipe cutter Sobol' study: " << desc.source_file << ", " << ne
            << " errors, N = " << opt.samples << ", bootstrap " << opt.bootstrap << ", " << threads
            << " threads\n";

  SobolOptions so;
  so.samples = opt.samples;
  so.sampling = Sampling::Qmc;
  so.seed = 1;
  so.intervals = SobolIntervals::Bootstrap;  // Jiang et al. 2021's table: bootstrap intervals
  so.bootstrap = opt.bootstrap;
  so.threads = threads;
  auto t0 = std::chrono::steady_clock::now();
  const SobolDesign design(inputs, so);
  const double design_seconds = seconds_since(t0);

  std::vector<OrderRun> runs;
  std::vector<TurnRow> turns;
  for (int order : opt.orders) {
    LoadOptions lo;
    lo.order = order;
    lo.builtins = builtin_models();
    lo.generate = generate_for_loader;
    lo.log = [](const std::string& m) { std::cerr << "weilgen: " << m << "\n"; };
    OrderRun run;
    run.order = order;
    run.errors = ne;
    run.entries.assign(kPoses * kOutputs * ne, Entry{});
    t0 = std::chrono::steady_clock::now();
    const std::shared_ptr<const Model> model_ptr = load_model(desc, lo);
    run.load_seconds = seconds_since(t0);
    const Model& model = *model_ptr;
    run.origin = model.origin();
    run.engine = engine_name(model.engine());
    std::cout << "order " << order << ": model origin: " << run.origin << " (loaded in "
              << duration(run.load_seconds) << ")\n";

    if (turns.empty()) turns = turning_table(model, desc, poses, inputs);
    // Exact indices of the linear model (the first-order reference; exact at order 1).
    ModelData data(model);
    for (std::size_t p = 0; p < kPoses; ++p) {
      model.coefficients(data, poses[p].data(), data.coeff.data());
      for (std::size_t o = 0; o < kOutputs; ++o) {
        const std::vector<double> c(data.coeff.begin() + o * ne, data.coeff.begin() + (o + 1) * ne);
        const std::vector<double> s = linear_sobol_indices(c, inputs);
        for (std::size_t i = 0; i < ne; ++i) run.at(p, o, i).S_exact = s[i];
      }
    }

    // Sampled indices: one ModelData per thread, as the sensitivity verb does.
    std::vector<ModelData> work;
    for (unsigned t = 0; t < threads; ++t) work.emplace_back(model);
    for (std::size_t p = 0; p < kPoses; ++p) {
      const double* pose = poses[p].data();
      const VectorFunction fn = [&](unsigned t, const double* x, double* y) {
        ModelData& w = work[t];
        model.deviation(w, pose, x, w.out.data());
        for (std::size_t o = 0; o < kOutputs; ++o) y[o] = w.out[o];
      };
      t0 = std::chrono::steady_clock::now();
      const SobolResult r = SobolAnalysis(so).run(design, kOutputs, fn);
      run.pose_seconds[p] = seconds_since(t0);
      run.sobol_seconds += run.pose_seconds[p];
      run.evaluations += r.evaluations;
      for (std::size_t o = 0; o < kOutputs; ++o) {
        const SobolIndices& s = r.outputs[o];
        run.stats[p][o] = {s.mean, s.variance};
        for (std::size_t i = 0; i < ne; ++i) {
          Entry& e = run.at(p, o, i);
          e.S = s.first[i], e.S_lo = s.first_lo[i], e.S_hi = s.first_hi[i];
          e.ST = s.total[i], e.ST_lo = s.total_lo[i], e.ST_hi = s.total_hi[i];
        }
      }
      std::cout << "  " << x_label(p) << ": " << r.evaluations << " evaluations, "
                << duration(run.pose_seconds[p]) << "\n";
    }
    std::cout << "order " << order << ": Sobol' " << duration(run.sobol_seconds) << " for "
              << run.evaluations << " evaluations ("
              << g3(1e9 * run.sobol_seconds / static_cast<double>(run.evaluations))
              << " ns each, bootstrap included)\n";
    runs.push_back(std::move(run));
  }

  std::vector<std::string> written;
  const auto out = [&](const std::string& name) {
    return (std::filesystem::path(opt.out) / name).string();
  };
  write_file_atomically(out("results.md"), results_markdown(desc, runs, turns, opt, threads,
                                                            design_seconds, so.confidence));
  written.push_back(out("results.md"));
  write_file_atomically(out("results.json"), results_json(desc, inputs, poses, runs, turns, opt,
                                                          threads, design_seconds, so.confidence)
                                                     .dump(1) +
                                                 "\n");
  written.push_back(out("results.json"));
  write_charts(desc, runs.front(), opt, written);

  std::cout << "\ndesign " << duration(design_seconds);
  for (const OrderRun& run : runs)
    std::cout << "; order " << run.order << ": load " << duration(run.load_seconds) << ", Sobol' "
              << duration(run.sobol_seconds);
  std::cout << "; total " << duration(seconds_since(start)) << "\nwrote:\n";
  for (const auto& w : written) std::cout << "  " << w << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse_options(argc, argv);
  try {
    return run(opt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
}
