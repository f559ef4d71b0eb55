// weilgen_gap_synth: writes the measurement sets of the sim-to-real gap benchmark
// (bench/gap/README.md). One scenario, the whole suite with fixed seeds, a self-check of the
// generator, or a probe of which errors a model could miss visibly.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
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

  weilgen_gap_synth --effect E[+E2] --factor F --noise-um S --layout L --seed N --out DIR
                    [--machine vmc_3axis] [--missing E_AX] [--truth-degree 3] [--fit-degree 3]
                    [--rotary-fourier H]
                    [--outliers N] [--hetero] [--observations N]
      one scenario: DIR/data.csv, DIR/data_oracle.csv (the same data with the withheld
      effects and the gross readings removed exactly) and DIR/truth.json; --observations N
      repeats the grid's
      cycles as often as needed and cuts the layout after N observations (the speed benchmark)
  weilgen_gap_synth --suite DIR [--quick] [--reps N] [--nones N] [--machines M1,M2]
                    [--layouts L1,L2] [--effects E1,E2,pairs,outliers,hetero] [--threads 2]
                    [--rotary-fourier H]
      the benchmark suite (fixed seeds): DIR/sNNNN/{data.csv,data_oracle.csv,truth.json},
      DIR/manifest.tsv
  --rotary-fourier H: a rotary axis' PDGEs are Fourier series of H harmonics over one turn (in
      the truth and in what defines "absorbable"; weilgen's default there is fourier:2), not
      Legendre cubics on the travel
  weilgen_gap_synth --self-check [--machines M1,M2]
      checks the generator against the exact chain and its own scaling; exit 1 on failure
  weilgen_gap_synth --probe-missing [--layout grid] [--machine vmc_3axis] [--seed N]
      for every error, the fraction of its signal a model without it could not absorb

Effects: thermal_drift reversal periodic pdge_shape higher_order missing_error tool_offset setup
step none. Layouts: grid sparse small line ballbar ballbar_yz rtest rtest_small. Machines of the
suite: vmc_3axis five_axis_ac head_head_bc.
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

// Leaves a file with the same text untouched, so that its timestamp still tells
// run_benchmark.sh --resume that the diagnosis on it is current.
void write_file(const fs::path& path, const std::string& text) {
  if (fs::is_regular_file(path) && fs::file_size(path) == text.size()) {
    std::ifstream f(path, std::ios::binary);
    std::string old(text.size(), '\0');
    if (f.read(old.data(), static_cast<std::streamsize>(old.size())) && old == text) return;
  }
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    if (!f) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

// A scenario's files in `dir`: the data, the oracle reference (the same truth, poses and noise
// without the withheld effects and gross readings; `weilgen gap` on it leaves what a model
// knowing them would) and the truth, which is returned.
json write_scenario_files(const Synthesiser& s, const fs::path& dir) {
  fs::create_directories(dir);
  write_file(dir / "data.csv", s.csv());
  write_file(dir / "data_oracle.csv", s.csv(false, true, false));
  json t = s.truth();
  write_file(dir / "truth.json", t.dump(2) + "\n");
  return t;
}

void write_scenario(const ScenarioSpec& spec, const fs::path& dir) {
  write_scenario_files(Synthesiser(spec), dir);
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

// The suite (README.md, "Scenario grid"). Seeds come from the scenario ids, so a scenario is the
// same whatever else the suite contains.
struct MachineLayouts {
  std::string machine;
  std::vector<std::string> layouts;
};

const std::vector<MachineLayouts>& suite_machines() {
  static const std::vector<MachineLayouts> m = {
      {"vmc_3axis", {"grid", "sparse", "small", "line", "ballbar", "ballbar_yz"}},
      {"five_axis_ac", {"rtest", "rtest_small", "line", "ballbar"}},
      {"head_head_bc", {"rtest", "rtest_small", "line", "ballbar_yz"}}};
  return m;
}

// Whether the suite withholds `effect` in `layout` (README.md, "Scenario grid"): shapes need an
// axis with 9 positions; second-order terms, missing errors, tool offsets and set-up errors only
// where the layout can see them at all (elsewhere the model absorbs them: they are probed by
// --self-check and documented, not scored again and again).
bool in_suite(const std::string& machine, const std::string& layout, const std::string& effect) {
  (void)machine;
  const bool rtest = Layout::parse(layout).rtest();
  if (effect == "periodic" || effect == "pdge_shape")
    return layout != "sparse" && layout != "small";
  if (effect == "higher_order") return layout == "grid" || layout == "rtest";
  if (effect == "missing_error") return layout == "grid" || layout == "sparse" || rtest;
  if (effect == "tool_offset") return false;
  if (effect == "setup") return false;
  return true;
}

std::vector<std::string> list_arg(const Args& args, const std::string& key) {
  return split(args.get(key, ""), ',');
}

bool selected(const std::vector<std::string>& filter, const std::string& x) {
  return filter.empty() || std::find(filter.begin(), filter.end(), x) != filter.end();
}

std::vector<SuiteEntry> suite_entries(const Args& args) {
  const bool quick = args.has("--quick");
  const std::vector<double> factors =
      quick ? std::vector<double>{3, 10} : std::vector<double>{3, 5, 10};
  const int reps = static_cast<int>(number("--reps", args.get("--reps", quick ? "1" : "2")));
  const int nones = static_cast<int>(number("--nones", args.get("--nones", quick ? "2" : "6")));
  const std::vector<std::string> machines = list_arg(args, "--machines");
  const std::vector<std::string> layouts = list_arg(args, "--layouts");
  const std::vector<std::string> only = list_arg(args, "--effects");
  const double noise_levels[2] = {0.5, 1.0};
  const int harmonics =
      static_cast<int>(number("--rotary-fourier", args.get("--rotary-fourier", "0")));
  std::vector<SuiteEntry> out;
  int li = 0;
  auto add = [&](const std::string& machine, const std::string& layout, const std::string& effect,
                 double f, int rep, const std::string& tag, int outliers, bool hetero) {
    SuiteEntry e;
    e.id = machine + "/" + layout + "/" + effect + "/f" + factor_text(f) + "/r" +
           std::to_string(rep) + tag;
    e.spec.machine = machine;
    e.spec.effect = effect;
    e.spec.factor = f;
    e.spec.layout = layout;
    e.spec.noise_um = noise_levels[(rep + li) % 2];
    e.spec.outliers = outliers;
    e.spec.heteroscedastic = hetero;
    e.spec.rotary_harmonics = harmonics;
    e.spec.seed = seed_from("weilgen-gap-bench-2/" + e.id);
    out.push_back(e);
  };
  std::vector<std::string> effects = library_effects();
  effects.push_back("step");
  const std::vector<std::string> pairs = {"reversal+thermal_drift", "periodic+reversal",
                                          "pdge_shape+thermal_drift", "reversal+pdge_shape"};
  for (const MachineLayouts& ml : suite_machines()) {
    if (!selected(machines, ml.machine)) continue;
    for (const std::string& layout : ml.layouts) {
      ++li;
      if (!selected(layouts, layout)) continue;
      const bool first = layout == ml.layouts.front();
      for (const std::string& effect : effects)
        if (in_suite(ml.machine, layout, effect) && selected(only, effect))
          for (double f : factors)
            for (int rep = 0; rep < reps; ++rep)
              add(ml.machine, layout, effect, f, rep, "", 0, false);
      if (selected(only, "none"))
        for (int rep = 0; rep < nones; ++rep) add(ml.machine, layout, "none", 0, rep, "", 0, false);
      // Two effects at once (both must be named): every pair on the machine's first layout,
      // backlash with a drift on the line.
      if (selected(only, "pairs"))
        for (const std::string& p : pairs)
          if (first || (layout == "line" && p == pairs[0]))
            for (double f : factors) add(ml.machine, layout, p, f, 0, "", 0, false);
      // Gross readings and heteroscedastic noise on the first layout and the line.
      if (first || layout == "line") {
        for (const char* effect : {"reversal", "thermal_drift", "none"}) {
          if (!selected(only, "outliers")) break;
          for (int rep = 0; rep < (quick ? 1 : 2); ++rep)
            add(ml.machine, layout, effect, std::string(effect) == "none" ? 0 : 5, rep, "/outliers",
                5, false);
        }
        for (const char* effect : {"reversal", "periodic", "thermal_drift", "none"}) {
          if (!selected(only, "hetero")) break;
          for (int rep = 0; rep < (quick ? 1 : 2); ++rep)
            add(ml.machine, layout, effect, std::string(effect) == "none" ? 0 : 5, rep, "/hetero",
                0, true);
        }
      }
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
        // Scenario directories are opaque (sNNNN) so nothing about the truth reaches the
        // diagnosis through a path; the manifest maps them to ids.
        const json t = write_scenario_files(s, dir / name);
        const std::string model = fs::is_regular_file(s.model_machine())
                                      ? fs::absolute(s.model_machine()).string()
                                      : s.model_machine();  // a shipped machine's name
        char extra[160];
        std::snprintf(extra, sizeof extra, "\t%s\t%.3g\t%.3g",
                      t["expected_verdict"].get<std::string>().c_str(),
                      t["effect"]["visible_fraction"].get<double>(),
                      t["effect"]["raw_signal_rms_um"].get<double>());
        lines[i] = std::string(name) + "\t" + entries[i].id + "\t" + model + extra;
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
void check_chain(Checker& ck, const std::string& machine, const std::string& layout,
                 int rotary_harmonics = 0) {
  ScenarioSpec spec;
  spec.machine = machine;
  spec.layout = layout;
  spec.rotary_harmonics = rotary_harmonics;
  spec.noise_um = 0;
  spec.seed = 7;
  const Synthesiser s(spec);
  const MeasurementTable t = parse(s.csv());
  const json truth = s.truth();
  const Description desc = load_machine_file(resolve_machine(machine));
  NumericChain chain(desc);
  const std::vector<int> axes = desc.axes();
  const std::vector<double> zero(desc.errors.size(), 0.0);
  std::vector<double> centre;
  if (t.has("dr_um")) {
    // The table ball: the tool point at the circle's centre pose (header key `centre`).
    std::map<std::string, double> c;
    for (const std::string& item : split(t.header_key("centre"), ',')) {
      const auto eq = item.find('=');
      c[std::string(trim(item.substr(0, eq)))] = std::stod(item.substr(eq + 1));
    }
    for (int b : axes)
      centre.push_back(c.at(desc.bodies[static_cast<std::size_t>(b)].joint.coordinate));
  }
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
        const bool fourier = je.contains("fourier");
        const json& c = je[fourier ? "fourier" : "legendre"];
        std::vector<double> p(c.size());
        const int n = static_cast<int>(p.size());
        pdge_basis(fourier ? (n - 1) / 2 : 0, n - 1, t.column(je["axis"].get<std::string>())[r], a,
                   b, p.data());
        for (std::size_t k = 0; k < p.size(); ++k) v += c[k].get<double>() * p[k];
      }
      e.push_back(v * je["to_base"].get<double>());
    }
    const std::array<double, 6> d = chain.deviation(q, e);
    if (t.has("dr_um")) {
      const Eigen::Vector3d v = chain.tool_in_workpiece(q, zero).block<3, 1>(0, 3) -
                                chain.tool_in_workpiece(centre, zero).block<3, 1>(0, 3);
      const Eigen::Vector3d dv(d[0], d[1], d[2]);
      worst = std::max(worst, std::abs(1000 * ((v + dv).norm() - v.norm()) - t.column("dr_um")[r]));
    } else {
      const char* names[3] = {"dx_um", "dy_um", "dz_um"};
      for (int k = 0; k < 3; ++k)
        if (t.has(names[k])) worst = std::max(worst, std::abs(1000 * d[k] - t.column(names[k])[r]));
    }
  }
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "%s/%s: none, noise 0: file = exact chain with truth.json errors (max |diff| "
                "%.2e um over %zu rows)",
                machine.c_str(), layout.c_str(), worst, t.rows());
  ck.check(worst < 1e-5 && t.rows() > 0, buf);
}

// Every effect: the file with the effects minus the file without them (both noise-free, read
// back through the CSV reader) has the requested held-out signal, each effect alone too; the
// noise has its sigma; gross readings are where truth.json says; the oracle file is the data file
// minus that signal and minus truth.json's gross readings, everything else unchanged.
void check_effect(Checker& ck, const std::string& machine, const std::string& layout,
                  const std::string& effect, int outliers = 0, bool hetero = false) {
  ScenarioSpec spec;
  spec.machine = machine;
  spec.layout = layout;
  spec.effect = effect;
  spec.factor = 3;
  spec.noise_um = 0.8;
  spec.outliers = outliers;
  spec.heteroscedastic = hetero;
  spec.seed = seed_from("self-check/" + machine + "/" + layout + "/" + effect);
  const Synthesiser s(spec);
  const json truth = s.truth();
  const auto& cols = s.measured_columns();
  const std::vector<double> on = observations(parse(s.csv(true, false)), cols);
  const std::vector<double> off = observations(parse(s.csv(false, false)), cols);
  const std::vector<double> noisy = observations(parse(s.csv(false, true)), cols);
  const MeasurementTable data_t = parse(s.csv()), oracle_t = parse(s.csv(false, true, false));
  const std::vector<double> data = observations(data_t, cols);
  const std::vector<double> oracle = observations(oracle_t, cols);
  std::vector<double> sig(on.size()), noise(on.size());
  for (std::size_t i = 0; i < on.size(); ++i) {
    sig[i] = on[i] - off[i];
    noise[i] = noisy[i] - off[i];
  }
  for (const json& g : truth["gross_readings"])
    noise[g["observation"].get<std::size_t>()] -= g["size_um"].get<double>();
  bool ok = true;
  std::string what;
  for (std::size_t k = 0; k < s.num_effects(); ++k) {
    const json& te = truth["effects"][k];
    const bool identifiable = te["identifiable"].get<bool>();
    const bool observable = te["observable"].get<bool>();
    const std::vector<double> one = s.num_effects() == 1 ? sig : s.effect_signal(k);
    const std::vector<double> v = identifiable ? s.unabsorbed_rms(one) : s.raw_rms(one);
    const double got = *std::max_element(v.begin(), v.end());
    const double want = observable ? spec.factor * spec.noise_um : 0.0;
    char buf[200];
    std::snprintf(buf, sizeof buf, "%s%s %s %.4f um (want %.4f), visible %.0f %%, expect %s",
                  what.empty() ? "" : "; ", te["name"].get<std::string>().c_str(),
                  !observable    ? "unseen"
                  : identifiable ? "held-out"
                                 : "raw",
                  got, want, 100 * te["visible_fraction"].get<double>(),
                  te["expected"].get<std::string>().c_str());
    what += buf;
    ok = ok && (observable ? std::abs(got / want - 1) < 2e-3 : got < 1e-3);
  }
  double ss = 0;
  for (double x : noise) ss += x * x;
  const double noise_rms = std::sqrt(ss / static_cast<double>(noise.size()));
  ok = ok && std::abs(noise_rms - truth["noise_rms_um"].get<double>()) < 1e-5 &&
       // The realised RMS of n draws: within 3 standard errors (1/sqrt(2n) relative).
       std::abs(noise_rms / spec.noise_um - 1) <
           3 / std::sqrt(2.0 * static_cast<double>(noise.size())) + 0.02 &&
       truth["gross_readings"].size() == static_cast<std::size_t>(outliers);
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s/%s: %s%s%s: ", machine.c_str(), layout.c_str(), effect.c_str(),
                outliers ? " +outliers" : "", hetero ? " +hetero" : "");
  std::snprintf(buf + std::strlen(buf), sizeof buf - std::strlen(buf),
                "noise rms %.3f (sigma %.3f); ", noise_rms, spec.noise_um);
  ck.check(ok, buf + what);

  std::vector<double> gross(data.size(), 0.0);
  for (const json& g : truth["gross_readings"])
    gross[g["observation"].get<std::size_t>()] += g["size_um"].get<double>();
  double worst = 0;
  for (std::size_t i = 0; i < data.size(); ++i)
    worst = std::max(worst, std::abs(data[i] - sig[i] - gross[i] - oracle[i]));
  // Poses, times, directions, cycles, temperatures and header lines: the same as the data's.
  bool same = data_t.columns == oracle_t.columns && data_t.header_keys == oracle_t.header_keys &&
              data_t.rows() == oracle_t.rows() && oracle.size() == data.size();
  for (const std::string& c : data_t.columns)
    if (std::find(cols.begin(), cols.end(), c) == cols.end())
      same = same && data_t.column(c) == oracle_t.column(c);
  std::snprintf(buf, sizeof buf,
                "%s/%s: %s: oracle file = data - effect signal - %zu gross readings (max |diff| "
                "%.1e um), other columns %s",
                machine.c_str(), layout.c_str(), effect.c_str(), truth["gross_readings"].size(),
                worst, same ? "equal" : "DIFFER");
  // Four values printed to 1e-6 um: at most 4 x 5e-7 apart.
  ck.check(same && worst < 2.5e-6, buf);
}

int self_check(const Args& args) {
  Checker ck;
  std::vector<std::string> machines = split(args.get("--machines", ""), ',');
  for (const MachineLayouts& ml : suite_machines()) {
    if (!selected(machines, ml.machine)) continue;
    for (const std::string& layout : ml.layouts) {
      check_chain(ck, ml.machine, layout);
      check_chain(ck, ml.machine, layout, 2);  // rotary PDGEs as Fourier series (truth.json)
    }
    for (const std::string& layout : ml.layouts) {
      std::vector<std::string> effects = library_effects();
      effects.push_back("step");
      for (const std::string& effect : effects) {
        if (!in_suite(ml.machine, layout, effect)) continue;
        try {
          check_effect(ck, ml.machine, layout, effect);
        } catch (const std::exception& e) {
          ck.check(false, ml.machine + "/" + layout + "/" + effect + ": " + e.what());
        }
      }
    }
    const std::string first = ml.layouts.front();
    try {
      check_effect(ck, ml.machine, first, "reversal+thermal_drift", 5, true);
      check_effect(ck, ml.machine, "line", "reversal", 5, false);
    } catch (const std::exception& e) {
      ck.check(false, ml.machine + ": " + e.what());
    }
    // Same seed, different effect: the truth machine and the noise are shared.
    ScenarioSpec a, b;
    a.seed = b.seed = 11;
    a.machine = b.machine = ml.machine;
    a.layout = b.layout = first;
    b.effect = "reversal";
    b.factor = 3;
    const json ta = Synthesiser(a).truth(), tb = Synthesiser(b).truth();
    ck.check(ta["truth_errors"] == tb["truth_errors"] && ta["noise_rms_um"] == tb["noise_rms_um"],
             ml.machine + ": one seed: same truth errors and noise whatever the effect");
    const std::string c1 = Synthesiser(b).csv(), c2 = Synthesiser(b).csv();
    ck.check(c1 == c2, ml.machine + ": deterministic: the same spec writes the same file");
  }
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
    spec.rotary_harmonics =
        static_cast<int>(number("--rotary-fourier", args.get("--rotary-fourier", "0")));
    spec.missing_error = args.get("--missing");
    spec.outliers = static_cast<int>(number("--outliers", args.get("--outliers", "0")));
    spec.heteroscedastic = args.has("--hetero");
    spec.observations = static_cast<int>(number("--observations", args.get("--observations", "0")));
    if (spec.observations < 0) throw std::runtime_error("--observations must be >= 0");
    write_scenario(spec, args.get("--out"));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "weilgen_gap_synth: %s\n", e.what());
    return 1;
  }
}
