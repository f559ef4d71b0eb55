// weilgen_gap_synth: writes the measurement sets of the sim-to-real gap benchmark
// (bench/gap/README.md). One scenario, the whole suite with fixed seeds, a self-check of the
// generator, or a probe of which errors a model could miss visibly.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "truth.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace weilgen;
using namespace weilgen::gapbench;

namespace {

const char* const kUsage = R"(weilgen_gap_synth: synthetic measurement sets for `weilgen gap`

  weilgen_gap_synth --effect E --factor F --noise-um S --layout L --seed N --out DIR
                    [--machine vmc_3axis] [--missing E_AX] [--truth-degree 3] [--fit-degree 3]
                    [--observations N]
      one scenario: DIR/data.csv and DIR/truth.json; --observations N repeats the layout's
      cycles as often as needed and cuts it after N observations (the speed benchmark)
  weilgen_gap_synth --suite DIR [--quick] [--reps N] [--layouts grid,line,ballbar]
                    [--machine vmc_3axis] [--threads 2]
      the benchmark suite (fixed seeds): DIR/sNNNN/{data.csv,truth.json}, DIR/manifest.tsv
  weilgen_gap_synth --self-check [--machine vmc_3axis]
      checks the generator against the exact chain and its own scaling; exit 1 on failure
  weilgen_gap_synth --probe-missing [--layout grid] [--machine vmc_3axis] [--seed N]
      for every error, the fraction of its signal a model without it could not absorb

Effects: thermal_drift reversal periodic pdge_shape higher_order missing_error tool_offset setup
step none. Layouts: grid line ballbar.
)";

struct Args {
  std::vector<std::string> v;
  std::string get(const std::string& key, const std::string& fallback = "") const {
    for (std::size_t i = 0; i + 1 < v.size(); ++i)
      if (v[i] == key) return v[i + 1];
    return fallback;
  }
  bool has(const std::string& key) const { return std::find(v.begin(), v.end(), key) != v.end(); }
};

double number(const std::string& key, const std::string& text) {
  std::size_t used = 0;
  double x = 0;
  try {
    x = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty())
    throw std::runtime_error(key + ": '" + text + "' is not a number");
  return x;
}

void write_file(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    if (!f) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

void write_scenario(const ScenarioSpec& spec, const fs::path& dir) {
  const Synthesiser s(spec);
  fs::create_directories(dir);
  write_file(dir / "data.csv", s.csv());
  write_file(dir / "truth.json", s.truth().dump(2) + "\n");
}

// ---------------------------------------------------------------------------------------------
// The suite

struct SuiteEntry {
  std::string id;
  ScenarioSpec spec;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string factor_text(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", f);
  return buf;
}

// Scenario grid (README.md, "Scenario grid"). Seeds come from the scenario ids, so a scenario
// is the same whatever else the suite contains.
std::vector<SuiteEntry> suite_entries(const Args& args) {
  const bool quick = args.has("--quick");
  const std::vector<double> factors =
      quick ? std::vector<double>{1, 3, 10} : std::vector<double>{1, 2, 3, 5, 10};
  const int reps = static_cast<int>(number("--reps", args.get("--reps", quick ? "1" : "4")));
  const int nones = static_cast<int>(number("--nones", args.get("--nones", quick ? "4" : "20")));
  const std::vector<std::string> layouts = split(args.get("--layouts", "grid,line,ballbar"), ',');
  const std::string machine = args.get("--machine", "vmc_3axis");
  const double noise_levels[2] = {0.5, 1.0};
  std::vector<SuiteEntry> out;
  for (std::size_t li = 0; li < layouts.size(); ++li) {
    const std::string& layout = layouts[li];
    std::vector<std::string> effects = library_effects();
    effects.push_back("step");
    for (const std::string& effect : effects) {
      // Combinations left out (README.md, "Scenario grid"): off the grid, second-order terms
      // escape the polynomials only with errors hundreds of times the spreads, and a line run
      // measures nothing of the roll E_AX.
      if (effect == "higher_order" && layout != "grid") continue;
      if (effect == "missing_error" && layout == "line") continue;
      for (double f : factors) {
        for (int rep = 0; rep < reps; ++rep) {
          SuiteEntry e;
          e.id = layout + "/" + effect + "/f" + factor_text(f) + "/r" + std::to_string(rep);
          e.spec.machine = machine;
          e.spec.effect = effect;
          e.spec.factor = f;
          e.spec.layout = layout;
          e.spec.noise_um = noise_levels[(rep + li) % 2];
          e.spec.seed = seed_from("weilgen-gap-bench-1/" + machine + "/" + e.id);
          out.push_back(e);
        }
      }
    }
    for (int rep = 0; rep < nones; ++rep) {
      SuiteEntry e;
      e.id = layout + "/none/f0/r" + std::to_string(rep);
      e.spec.machine = machine;
      e.spec.effect = "none";
      e.spec.layout = layout;
      e.spec.noise_um = noise_levels[(rep + li) % 2];
      e.spec.seed = seed_from("weilgen-gap-bench-1/" + machine + "/" + e.id);
      out.push_back(e);
    }
  }
  return out;
}

int run_suite(const Args& args) {
  const fs::path dir = args.get("--suite");
  const std::vector<SuiteEntry> entries = suite_entries(args);
  const int threads =
      std::max(1, static_cast<int>(number("--threads", args.get("--threads", "2"))));
  fs::create_directories(dir);
  std::vector<std::string> lines(entries.size());
  std::atomic<std::size_t> next{0};
  std::mutex mu;
  std::string error;
  const auto t0 = std::chrono::steady_clock::now();
  auto work = [&] {
    for (std::size_t i = next++; i < entries.size(); i = next++) {
      char name[32];
      std::snprintf(name, sizeof name, "s%04zu", i + 1);
      try {
        const Synthesiser s(entries[i].spec);
        const fs::path sd = dir / name;
        fs::create_directories(sd);
        write_file(sd / "data.csv", s.csv());
        // Scenario directories are opaque (sNNNN) so nothing about the truth reaches the
        // diagnosis through a path; the manifest maps them to ids.
        const std::string model = fs::is_regular_file(s.model_machine())
                                      ? fs::absolute(s.model_machine()).string()
                                      : s.model_machine();  // a shipped machine's name
        const json t = s.truth();
        char extra[96];
        std::snprintf(extra, sizeof extra, "\t%s\t%.3g\t%.3g",
                      t["expected_verdict"].get<std::string>().c_str(),
                      t["effect"]["visible_fraction"].get<double>(),
                      t["effect"]["raw_signal_rms_um"].get<double>());
        lines[i] = std::string(name) + "\t" + entries[i].id + "\t" + model + extra;
        write_file(sd / "truth.json", t.dump(2) + "\n");
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mu);
        if (error.empty()) error = entries[i].id + ": " + e.what();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(work);
  for (auto& t : pool) t.join();
  if (!error.empty()) {
    std::fprintf(stderr, "weilgen_gap_synth: %s\n", error.c_str());
    return 1;
  }
  std::string manifest =
      "# dir\tid\tmodel_machine\texpected_verdict\tvisible_fraction\traw_signal_rms_um\n";
  for (const std::string& l : lines) manifest += l + "\n";
  write_file(dir / "manifest.tsv", manifest);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %zu scenarios to %s in %.1f s\n", entries.size(), dir.string().c_str(), secs);
  return 0;
}

// ---------------------------------------------------------------------------------------------
// Self-check

struct Checker {
  int failures = 0;
  void check(bool ok, const std::string& what) {
    std::printf("%s  %s\n", ok ? "ok  " : "FAIL", what.c_str());
    if (!ok) ++failures;
  }
};

MeasurementTable parse(const std::string& text) { return parse_measurements(text, "synth.csv"); }

// The measured values of a parsed file in the generator's observation order.
std::vector<double> observations(const MeasurementTable& t, const std::vector<std::string>& cols) {
  std::vector<double> out;
  for (std::size_t r = 0; r < t.rows(); ++r)
    for (const std::string& c : cols) out.push_back(t.column(c)[r]);
  return out;
}

// Effect none, noise 0: every deviation in the file equals the exact chain at the row's pose
// with the truth errors rebuilt from truth.json alone (not from the generator's state).
void check_chain(Checker& ck, const std::string& machine, const std::string& layout) {
  ScenarioSpec spec;
  spec.machine = machine;
  spec.layout = layout;
  spec.noise_um = 0;
  spec.seed = 7;
  const Synthesiser s(spec);
  const MeasurementTable t = parse(s.csv());
  const json truth = s.truth();
  const Description desc = load_machine_file(resolve_machine(machine));
  NumericChain chain(desc);
  const std::vector<int> axes = desc.axes();
  double worst = 0;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    std::vector<double> q(axes.size());
    for (std::size_t k = 0; k < axes.size(); ++k)
      q[k] = t.column(desc.bodies[static_cast<std::size_t>(axes[k])].joint.coordinate)[r];
    std::vector<double> e;
    for (const json& je : truth["truth_errors"]) {
      double v = 0;
      if (je["dependence"] == "PIGE") {
        v = je["value"].get<double>();
      } else {
        const double a = je["travel"][0].get<double>(), b = je["travel"][1].get<double>();
        const double u = (2 * t.column(je["axis"].get<std::string>())[r] - a - b) / (b - a);
        std::vector<double> p(je["legendre"].size());
        legendre(static_cast<int>(p.size()) - 1, u, p.data());
        for (std::size_t k = 0; k < p.size(); ++k) v += je["legendre"][k].get<double>() * p[k];
      }
      e.push_back(v * je["to_base"].get<double>());
    }
    const std::array<double, 6> d = chain.deviation(q, e);
    if (layout == "ballbar") {
      const double radius = std::stod(t.header_key("radius"));
      const double th = t.column("angle_deg")[r] * M_PI / 180;
      Eigen::Vector3d p(d[0], d[1], d[2]);
      p[0] += radius * std::cos(th);  // vmc/gantry ballbar plane: XY
      p[1] += radius * std::sin(th);
      worst = std::max(worst, std::abs(1000 * (p.norm() - radius) - t.column("dr_um")[r]));
    } else {
      const char* names[3] = {"dx_um", "dy_um", "dz_um"};
      for (int k = 0; k < 3; ++k)
        if (t.has(names[k])) worst = std::max(worst, std::abs(1000 * d[k] - t.column(names[k])[r]));
    }
  }
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "%s/%s: none, noise 0: file = exact chain with truth.json errors (max |diff| "
                "%.2e um over %zu rows)",
                machine.c_str(), layout.c_str(), worst, t.rows());
  ck.check(worst < 1e-5 && t.rows() > 0, buf);
}

// Every effect: the file with the effect minus the file without it (both noise-free, read back
// through the CSV reader) has the requested held-out signal; the noise has its sigma.
void check_effect(Checker& ck, const std::string& machine, const std::string& layout,
                  const std::string& effect) {
  ScenarioSpec spec;
  spec.machine = machine;
  spec.layout = layout;
  spec.effect = effect;
  spec.factor = 3;
  spec.noise_um = 0.8;
  spec.seed = seed_from("self-check/" + layout + "/" + effect);
  const Synthesiser s(spec);
  const json truth = s.truth();
  const auto& cols = s.measured_columns();
  const std::vector<double> on = observations(parse(s.csv(true, false)), cols);
  const std::vector<double> off = observations(parse(s.csv(false, false)), cols);
  const std::vector<double> noisy = observations(parse(s.csv(false, true)), cols);
  std::vector<double> sig(on.size()), noise(on.size());
  for (std::size_t i = 0; i < on.size(); ++i) {
    sig[i] = on[i] - off[i];
    noise[i] = noisy[i] - off[i];
  }
  const bool identifiable = truth["effect"]["identifiable"].get<bool>();
  const std::vector<double> v = identifiable ? s.unabsorbed_rms(sig) : s.raw_rms(sig);
  const double got = *std::max_element(v.begin(), v.end());
  // An effect that does not reach this layout's measured values is left unscaled.
  const bool observable = truth["effect"]["observable"].get<bool>();
  const double want = observable ? spec.factor * spec.noise_um : 0.0;
  double ss = 0;
  for (double x : noise) ss += x * x;
  const double noise_rms = std::sqrt(ss / static_cast<double>(noise.size()));
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%s/%s: %-13s %s signal %.4f um (want %.4f), visible %.0f %%, noise rms %.3f "
                "(sigma %.3f), expect %s",
                machine.c_str(), layout.c_str(), effect.c_str(),
                !observable    ? "unseen  "
                : identifiable ? "held-out"
                               : "raw     ",
                got, want, 100 * truth["effect"]["visible_fraction"].get<double>(), noise_rms,
                spec.noise_um, truth["expected_verdict"].get<std::string>().c_str());
  const bool scaled = observable ? std::abs(got / want - 1) < 2e-3
                                 : got < 1e-3 && truth["expected_verdict"] != effect;
  const bool ok = scaled && std::abs(noise_rms - truth["noise_rms_um"].get<double>()) < 1e-5 &&
                  std::abs(noise_rms / spec.noise_um - 1) < 0.1;
  ck.check(ok, buf);
}

int self_check(const Args& args) {
  const std::string machine = args.get("--machine", "vmc_3axis");
  Checker ck;
  for (const std::string& layout : layout_names()) check_chain(ck, machine, layout);
  for (const std::string& layout : layout_names()) {
    std::vector<std::string> effects = library_effects();
    effects.push_back("step");
    for (const std::string& effect : effects) {
      try {
        check_effect(ck, machine, layout, effect);
      } catch (const std::exception& e) {
        ck.check(false, layout + "/" + effect + ": " + e.what());
      }
    }
  }
  // Same seed, different effect: the truth machine and the noise are shared.
  ScenarioSpec a, b;
  a.seed = b.seed = 11;
  a.machine = b.machine = machine;
  b.effect = "reversal";
  b.factor = 3;
  const json ta = Synthesiser(a).truth(), tb = Synthesiser(b).truth();
  ck.check(ta["truth_errors"] == tb["truth_errors"] && ta["noise_rms_um"] == tb["noise_rms_um"],
           "one seed: same truth errors and noise whatever the effect");
  const std::string c1 = Synthesiser(b).csv(), c2 = Synthesiser(b).csv();
  ck.check(c1 == c2, "deterministic: the same spec writes the same file");
  std::printf("%s: %d failure(s)\n", ck.failures ? "FAILED" : "passed", ck.failures);
  return ck.failures ? 1 : 0;
}

int probe_missing(const Args& args) {
  ScenarioSpec spec;
  spec.machine = args.get("--machine", "vmc_3axis");
  spec.layout = args.get("--layout", "grid");
  spec.seed = static_cast<std::uint64_t>(number("--seed", args.get("--seed", "1")));
  const Synthesiser s(spec);
  std::printf("%s, %s layout: fraction of each error's signal a model without it cannot absorb\n",
              spec.machine.c_str(), spec.layout.c_str());
  for (const auto& [name, frac] : s.missing_error_visibility())
    std::printf("  %-8s %6.1f %%\n", name.c_str(), 100 * frac);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  for (int i = 1; i < argc; ++i) args.v.emplace_back(argv[i]);
  try {
    if (args.v.empty() || args.has("--help") || args.has("-h")) {
      std::fputs(kUsage, args.v.empty() ? stderr : stdout);
      return args.v.empty() ? 2 : 0;
    }
    if (args.has("--self-check")) return self_check(args);
    if (args.has("--probe-missing")) return probe_missing(args);
    if (args.has("--suite")) return run_suite(args);
    if (!args.has("--out")) {
      std::fputs(kUsage, stderr);
      return 2;
    }
    ScenarioSpec spec;
    spec.machine = args.get("--machine", spec.machine);
    spec.effect = args.get("--effect", spec.effect);
    spec.factor = number("--factor", args.get("--factor", "0"));
    spec.noise_um = number("--noise-um", args.get("--noise-um", "1"));
    spec.layout = args.get("--layout", spec.layout);
    spec.seed = static_cast<std::uint64_t>(number("--seed", args.get("--seed", "1")));
    spec.truth_degree = static_cast<int>(number("--truth-degree", args.get("--truth-degree", "3")));
    spec.fit_degree = static_cast<int>(number("--fit-degree", args.get("--fit-degree", "3")));
    spec.missing_error = args.get("--missing");
    spec.observations = static_cast<int>(number("--observations", args.get("--observations", "0")));
    if (spec.observations < 0) throw std::runtime_error("--observations must be >= 0");
    write_scenario(spec, args.get("--out"));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "weilgen_gap_synth: %s\n", e.what());
    return 1;
  }
}
