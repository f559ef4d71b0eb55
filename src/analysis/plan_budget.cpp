// Several instruments within a time budget (`weilgen plan --instruments ... --time-budget`,
// docs/planning.md "Several instruments"): which set-ups and units to measure.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "plan_internal.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace weilgen {

InstrumentTimes default_instrument_times(Instrument i) {
  switch (i) {
    case Instrument::Points:
      return {3600, 60};  // a tracker and its reference; 1 min a pose
    case Instrument::Line6d:
      return {2700, 30};  // aligning the laser on an axis; 30 s a position
    case Instrument::Ballbar:
      return {300, 120};  // moving the pivot; a circle both ways
    case Instrument::RTest:
      return {1800, 30};  // the nest, the sphere, the sensors' zero
  }
  return {};
}

std::map<Instrument, InstrumentTimes> read_instrument_times(const std::string& path) {
  std::map<Instrument, InstrumentTimes> out;
  for (Instrument i :
       {Instrument::Points, Instrument::Line6d, Instrument::Ballbar, Instrument::RTest})
    out[i] = default_instrument_times(i);
  if (path.empty()) return out;
  std::string text;
  read_file(path, text);
  const YAML::Node root = parse_yaml(text, path);
  auto loc = [&](const YAML::Node& n) {
    const YAML::Mark m = n.Mark();
    return m.is_null() || m.line < 0 ? SourceLoc{path, 0, 0}
                                     : SourceLoc{path, m.line + 1, m.column + 1};
  };
  if (!root.IsMap())
    throw InputError({path, 1, 1},
                     "a times file is a YAML mapping of instruments (points, line6d, ballbar, "
                     "rtest) to {setup: 30 min, pose: 1 min}");
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string name = it->first.Scalar();
    Instrument inst;
    try {
      inst = parse_instrument(name, "instrument");
    } catch (const std::invalid_argument& e) {
      throw InputError(loc(it->first), std::string("unknown ") + e.what());
    }
    const YAML::Node v = it->second;
    if (!v.IsMap()) throw InputError(loc(v), name + ": expected {setup: TIME, pose: TIME}");
    for (auto k = v.begin(); k != v.end(); ++k) {
      const std::string key = k->first.Scalar();
      if (key != "setup" && key != "pose")
        throw InputError(loc(k->first), name + ": unknown key '" + key + "' (setup, pose)");
      if (!k->second.IsScalar())
        throw InputError(loc(k->second), name + "." + key + ": expected a time");
      double s = 0;
      try {
        s = parse_duration_s(k->second.Scalar(), "min", name + "." + key);
      } catch (const std::invalid_argument& e) {
        throw InputError(loc(k->second), e.what());
      }
      if (!(s >= 0)) throw InputError(loc(k->second), name + "." + key + ": must be >= 0");
      if (key == "pose" && !(s > 0)) throw InputError(loc(k->second), name + ".pose: must be > 0");
      (key == "setup" ? out[inst].setup_s : out[inst].pose_s) = s;
    }
  }
  return out;
}

namespace plan_detail {

namespace {

// Larger log det and λ_min, smaller traces; −inf and inf order singular designs last.
bool better(double a, double b, DesignCriterion c) {
  return c == DesignCriterion::D || c == DesignCriterion::E ? a > b : a < b;
}

// The value of a design with a regular information matrix (a singular one is −inf for D, +inf
// for A and I, 0 for E).
bool regular_value(double v, DesignCriterion c) {
  return c == DesignCriterion::E ? v > 0 : std::isfinite(v);
}

struct Choice {
  ExchangeResult exchange;  // `selected`: candidate indices
  double ridged = 0;        // the value with the exchange's ridge
  double time_s = 0;
  bool found() const { return !exchange.selected.empty(); }
};

// The set-ups a selection of candidate units uses, with their units and times.
std::vector<TimeUse> time_use(const PlanCandidates& c, const std::vector<std::size_t>& selected) {
  std::vector<TimeUse> out;
  std::set<std::size_t> setups;
  for (std::size_t j : selected) setups.insert(c.units[j].setup);
  for (std::size_t s : setups) {
    TimeUse t;
    t.setup = s;
    t.units = static_cast<std::size_t>(std::count_if(
        selected.begin(), selected.end(), [&](std::size_t j) { return c.units[j].setup == s; }));
    t.setup_s = c.setups[s].setup_s;
    t.units_s = c.setups[s].pose_s * static_cast<double>(t.units);
    out.push_back(t);
  }
  return out;
}

// Each unit's rows enter the criteria only through ZᵀZ: a circle's hundreds of rows become as
// many as its rank (L with LᵀL = ZᵀZ), which the exchange's updates are cubic in.
std::vector<MatrixXd> compact_units(const Frame& frame) {
  const Eigen::Index r = frame.Q.cols();
  std::vector<MatrixXd> out(frame.Z.size());
  for (std::size_t j = 0; j < frame.Z.size(); ++j) {
    const MatrixXd& z = frame.Z[j];
    if (z.rows() <= r) {
      out[j] = z;
      continue;
    }
    const Eigen::SelfAdjointEigenSolver<MatrixXd> es(MatrixXd(z.transpose() * z));
    const double cut = 1e-14 * std::max(es.eigenvalues().maxCoeff(), 0.0);
    const Eigen::Index keep = (es.eigenvalues().array() > cut).count();
    out[j] =
        (es.eigenvectors().rightCols(keep) * es.eigenvalues().tail(keep).cwiseSqrt().asDiagonal())
            .transpose();
  }
  return out;
}

// The rank of the information of a choice of set-ups (`mask` over `bit_of`). A loose cut counts
// near-null directions as present: a choice is skipped only when it surely cannot reach the rank.
Eigen::Index union_rank(const std::vector<MatrixXd>& setup_info,
                        const std::vector<std::size_t>& bit_of, std::size_t mask) {
  const Eigen::Index r = setup_info.front().rows();
  MatrixXd m = MatrixXd::Zero(r, r);
  for (std::size_t s = 0; s < setup_info.size(); ++s)
    if (mask >> bit_of[s] & 1) m += setup_info[s];
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<MatrixXd>(m).eigenvalues();
  const double cut = 1e-13 * std::max(ev.maxCoeff(), 0.0);
  return static_cast<Eigen::Index>((ev.array() > cut).count());
}

}  // namespace

void plan_budget(Context& cx, PlanResult& R) {
  const PlanInput& in = cx.in;
  const PlanOptions& o = cx.o;
  const PlanCandidates& c = in.candidates;
  // The choices: each set-up of several units (points, a 6D line's axis, an R-test nest) is
  // measured or not; ballbar circles, one unit each, are chosen one by one (their set-up time
  // is in their cost) once ballbars are allowed.
  // bit_of[s]: the bit of the choice that opens set-up s (one per multi-unit set-up, one after
  // them for every ballbar circle).
  std::size_t groups = 0;
  for (const PlanSetup& s : c.setups)
    if (s.instrument != Instrument::Ballbar) ++groups;
  std::vector<std::size_t> bit_of;
  bool ballbar = false;
  for (std::size_t s = 0, g = 0; s < c.setups.size(); ++s) {
    ballbar |= c.setups[s].instrument == Instrument::Ballbar;
    bit_of.push_back(c.setups[s].instrument == Instrument::Ballbar ? groups : g++);
  }
  const std::size_t bits = groups + (ballbar ? 1 : 0);
  if (bits > 12)
    throw std::invalid_argument("--instruments: " + std::to_string(groups) +
                                " set-ups to choose among is more than 12 (give fewer --nest)");
  auto instruments_in = [&](std::size_t mask) {
    std::set<Instrument> used;
    for (std::size_t s = 0; s < c.setups.size(); ++s)
      if (mask >> bit_of[s] & 1) used.insert(c.setups[s].instrument);
    return used;
  };
  // The information of every set-up's candidates together: a choice of set-ups whose union
  // cannot reach the candidates' rank plans a singular design, which loses to any regular one.
  const Eigen::Index r = cx.frame.Q.cols();
  std::vector<MatrixXd> setup_info(c.setups.size(), MatrixXd::Zero(r, r));
  for (std::size_t j = 0; j < c.units.size(); ++j)
    setup_info[c.units[j].setup].noalias() += cx.frame.Z[j].transpose() * cx.frame.Z[j];
  const std::vector<MatrixXd> compact = compact_units(cx.frame);
  Choice best;
  std::map<Instrument, Choice> alone;
  auto run_mask = [&](std::size_t mask) {
    // The multi-unit set-ups' time comes off the budget; a circle's is in its cost.
    double fixed = 0;
    std::vector<char> open(c.setups.size(), 0);
    for (std::size_t s = 0; s < c.setups.size(); ++s) {
      open[s] = mask >> bit_of[s] & 1;
      if (open[s] && c.setups[s].instrument != Instrument::Ballbar) fixed += c.setups[s].setup_s;
    }
    if (fixed > o.budget_s) return;
    DesignProblem p;
    std::vector<std::size_t> index;  // problem unit -> candidate
    for (std::size_t j = 0; j < c.units.size(); ++j) {
      const PlanSetup& s = c.setups[c.units[j].setup];
      if (!open[c.units[j].setup]) continue;
      index.push_back(j);
      p.units.push_back(compact[j]);
      p.cost.push_back(s.instrument == Instrument::Ballbar ? s.setup_s + s.pose_s : s.pose_s);
    }
    bool forced_ok = true;
    for (std::size_t f : c.forced) {
      const auto at = std::find(index.begin(), index.end(), f);
      if (at == index.end())
        forced_ok = false;
      else
        p.forced.push_back(static_cast<std::size_t>(at - index.begin()));
    }
    if (!forced_ok || p.units.empty()) return;
    p.budget = o.budget_s - fixed;
    if (*std::min_element(p.cost.begin(), p.cost.end()) > p.budget) return;
    p.weight = cx.frame.W;
    ExchangeOptions eo;
    eo.criterion = o.criterion;
    eo.restarts = std::min<std::size_t>(o.restarts, 3);
    eo.seed = o.seed + mask;
    eo.threads = o.threads;
    Choice ch;
    ch.exchange = ExchangeDesign(eo).run(p);
    for (std::size_t& j : ch.exchange.selected) j = index[j];
    if (!ch.found()) return;
    for (const TimeUse& t : time_use(c, ch.exchange.selected)) ch.time_s += t.setup_s + t.units_s;
    // Among equals (singular designs all −inf): the ridge's value, then the shorter time.
    ch.ridged = ch.exchange.restart_values[ch.exchange.best_restart];
    auto take = [&](Choice& slot) {
      const double v = ch.exchange.value, w = slot.exchange.value;
      if (!slot.found() || better(v, w, o.criterion) ||
          (v == w && (better(ch.ridged, slot.ridged, o.criterion) ||
                      (ch.ridged == slot.ridged && ch.time_s < slot.time_s))))
        slot = ch;
    };
    take(best);
    const std::set<Instrument> used = instruments_in(mask);
    if (used.size() == 1) take(alone[*used.begin()]);
  };
  // First the choices whose union reaches the rank, then, when one of them gave a regular
  // design, only the single-instrument ones (each instrument alone, for the comparison);
  // otherwise every choice (the best singular design, by its ridge).
  std::vector<char> done(std::size_t{1} << bits, 0);
  for (std::size_t mask = 1; mask < (std::size_t{1} << bits); ++mask)
    if (union_rank(setup_info, bit_of, mask) >= r) {
      run_mask(mask);
      done[mask] = 1;
    }
  const bool regular = best.found() && regular_value(best.exchange.value, o.criterion);
  for (std::size_t mask = 1; mask < (std::size_t{1} << bits); ++mask)
    if (!done[mask] && (!regular || instruments_in(mask).size() == 1)) run_mask(mask);
  if (!best.found())
    throw std::invalid_argument("--time-budget: no set-up and unit fit in " +
                                format_significant(o.budget_s / 3600, 3) + " h");
  R.exchange = best.exchange;
  R.plan = evaluate_candidates(cx, "plan", best.exchange.selected);
  R.plan.name = "plan";
  R.time_used_s = best.time_s;
  R.time_use = time_use(c, best.exchange.selected);
  for (auto& [inst, ch] : alone) {
    if (!ch.found()) continue;
    LayoutFigures f = evaluate_candidates(cx, std::string(instrument_name(inst)) + " alone",
                                          ch.exchange.selected);
    f.time_s = ch.time_s;
    f.lost = R.candidate_rank > f.rank ? R.candidate_rank - f.rank : 0;
    R.compare.push_back(f);
  }
}

}  // namespace plan_detail
}  // namespace weilgen
