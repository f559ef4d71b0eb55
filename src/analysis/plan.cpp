// The planner of `weilgen plan` (docs/planning.md, "How"): the candidates' estimable space as the
// frame of the exchange, the exchange, the exact evaluation of a layout as identify will estimate
// from it, and the comparison layouts.
#include "weilgen/analysis/plan.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>

#include "plan_internal.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/memory.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/uq/lsq.hpp"

namespace weilgen {

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

using namespace plan_detail;

// ---- Comparison layouts ------------------------------------------------------------------------

// Levels per axis whose product is at most n (each at least 2 when n allows), the largest such
// product, then the most balanced.
std::vector<std::size_t> balanced_factors(std::size_t n, std::size_t k) {
  std::vector<std::size_t> best, cur;
  std::size_t best_prod = 0;
  double best_ratio = 1e300;
  const std::size_t low = n >= (std::size_t{1} << k) ? 2 : 1;
  std::function<void(std::size_t, std::size_t)> rec = [&](std::size_t prod, std::size_t from) {
    if (cur.size() == k) {
      const double ratio = static_cast<double>(*std::max_element(cur.begin(), cur.end())) /
                           static_cast<double>(*std::min_element(cur.begin(), cur.end()));
      if (prod > best_prod || (prod == best_prod && ratio < best_ratio))
        best = cur, best_prod = prod, best_ratio = ratio;
      return;
    }
    for (std::size_t f = from; prod * f <= n; ++f) {
      cur.push_back(f);
      rec(prod * f, f);
      cur.pop_back();
    }
  };
  if (k == 0) return {};
  rec(1, low);
  std::sort(best.rbegin(), best.rend());
  return best;
}

std::vector<double> spread(double lo, double hi, std::size_t n, bool turn, double turn_size) {
  std::vector<double> v(n, lo);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = turn     ? lo + turn_size * static_cast<double>(i) / static_cast<double>(n)
           : n == 1 ? (lo + hi) / 2
                    : lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n - 1);
  return v;
}

// The regular layout of n units: a grid over the candidates' varying axes (points; the rotary
// axes of an R-test, the linear ones following the nest), equally spaced positions on each axis
// of a 6D line, circles spread evenly through the candidates (ballbar). Poses the instrument
// cannot take, and the units a grid of fewer poses leaves, are random candidates.
std::vector<PlanUnit> regular_layout(const PlanInput& in, std::size_t n, std::string& name,
                                     std::uint64_t seed) {
  const Description& d = in.model->description();
  const PlanCandidates& c = in.candidates;
  const std::size_t na = d.axes().size();
  std::vector<PlanUnit> out;
  // Per axis: the candidates' range and number of levels.
  std::vector<double> lo(na, INFINITY), hi(na, -INFINITY);
  std::vector<std::vector<double>> distinct(na);
  for (const PlanUnit& u : c.units)
    for (std::size_t a = 0; a < na; ++a) {
      lo[a] = std::min(lo[a], u.pose[a]);
      hi[a] = std::max(hi[a], u.pose[a]);
      if (distinct[a].size() < 1000 &&
          std::find(distinct[a].begin(), distinct[a].end(), u.pose[a]) == distinct[a].end())
        distinct[a].push_back(u.pose[a]);
    }
  if (in.instrument == Instrument::Points || in.instrument == Instrument::RTest) {
    std::vector<std::size_t> vary;
    for (std::size_t a = 0; a < na; ++a) {
      const bool rot = d.axis_joint(a).type == JointType::Revolute;
      if (in.instrument == Instrument::RTest && !rot) continue;
      if (distinct[a].size() > 1) vary.push_back(a);
    }
    // More levels to the axes with more candidate levels.
    std::stable_sort(vary.begin(), vary.end(), [&](std::size_t x, std::size_t y) {
      return distinct[x].size() > distinct[y].size();
    });
    const std::size_t setups = in.instrument == Instrument::RTest ? c.setups.size() : 1;
    std::vector<std::string> shape;
    for (std::size_t s = 0; s < setups; ++s) {
      const std::size_t share = n / setups + (s < n % setups ? 1 : 0);
      const std::vector<std::size_t> fac = balanced_factors(share, vary.size());
      const PlanUnit* base = nullptr;
      for (const PlanUnit& u : c.units)
        if (u.setup == s && !base) base = &u;
      if (!base) continue;
      std::vector<std::vector<double>> levels(na);
      for (std::size_t a = 0; a < na; ++a) levels[a] = {base->pose[a]};
      for (std::size_t i = 0; i < vary.size(); ++i) {
        const std::size_t a = vary[i];
        const Joint& j = d.axis_joint(a);
        const bool turn =
            j.type == JointType::Revolute && (j.max - j.min) * j.to_base >= 2 * kPi - 1e-9;
        levels[a] = spread(lo[a], hi[a], fac[i], turn, 2 * kPi / j.to_base);
      }
      if (s == 0)
        for (std::size_t f : fac) shape.push_back(std::to_string(f));
      std::vector<std::size_t> digit(na, 0);
      for (bool more = true; more;) {
        PlanUnit u{s, {}, 0};
        for (std::size_t a = 0; a < na; ++a) u.pose.push_back(levels[a][digit[a]]);
        if (in.instrument != Instrument::RTest || hold_nest(*in.model, c.setups[s], u.pose))
          out.push_back(u);
        more = false;
        for (std::size_t a = na; a-- > 0;) {
          if (++digit[a] < levels[a].size()) {
            more = true;
            break;
          }
          digit[a] = 0;
        }
      }
    }
    name = "grid";
    for (std::size_t i = 0; i < shape.size(); ++i) name += (i ? "x" : " ") + shape[i];
  } else if (in.instrument == Instrument::Line6d) {
    const std::size_t setups = c.setups.size();
    for (std::size_t s = 0; s < setups; ++s) {
      const std::size_t share = n / setups + (s < n % setups ? 1 : 0);
      std::size_t a = 0;
      while (d.axis_joint(a).coordinate != c.setups[s].axis) ++a;
      const PlanUnit* base = nullptr;
      for (const PlanUnit& u : c.units)
        if (u.setup == s && !base) base = &u;
      if (!base) continue;
      for (double v : spread(lo[a], hi[a], share, false, 0)) {
        PlanUnit u{s, base->pose, v * d.axis_joint(a).to_base};
        u.pose[a] = v;
        out.push_back(u);
      }
    }
    name = "equally spaced positions";
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const auto j =
          static_cast<std::size_t>((static_cast<double>(i) + 0.5) *
                                   static_cast<double>(c.units.size()) / static_cast<double>(n));
      out.push_back(c.units[std::min(j, c.units.size() - 1)]);
    }
    name = "circles spread evenly";
  }
  // Up to n with random candidates.
  std::uint64_t state = mix(seed + 4242);
  for (std::size_t guard = 0; out.size() < n && guard < 100 * n; ++guard) {
    state = mix(state + 0x9E3779B97F4A7C15ull);
    out.push_back(c.units[static_cast<std::size_t>(state % c.units.size())]);
  }
  if (out.size() > n) out.resize(n);
  return out;
}

}  // namespace

// ---- Noise and options
// ---------------------------------------------------------------------------

KindNoise parse_noise(const std::vector<std::string>& items, KindNoise base) {
  if (base[0] == 0) {
    for (std::size_t k = 0; k < kObservationKinds; ++k)
      base[k] = std::string(observation_unit(k)) == "µrad" ? 1.0 : 1.0;
  }
  for (const std::string& flag : items) {
    for (const std::string& raw : split(flag, ',')) {
      const std::string item = trim(raw);
      const std::string context = "--noise " + quoted(item);
      if (item.empty()) throw std::invalid_argument("--noise: empty item in " + quoted(flag));
      const auto eq = item.find('=');
      const std::string kind = eq == std::string::npos ? "" : trim(item.substr(0, eq));
      const std::string value = eq == std::string::npos ? item : trim(item.substr(eq + 1));
      std::size_t k = kObservationKinds;
      if (!kind.empty()) {
        for (std::size_t i = 0; i < kObservationKinds; ++i)
          if (kind == observation_name(i)) k = i;
        if (k == kObservationKinds)
          throw std::invalid_argument(context + ": unknown kind '" + kind +
                                      "' (dx, dy, dz, da, db, dc, dr, lin, str, ang)");
      }
      const bool angle = k < kObservationKinds && std::string(observation_unit(k)) == "µrad";
      const Quantity q =
          parse_quantity_unit(value, k < kObservationKinds && angle ? "urad" : "um", context);
      if (k < kObservationKinds && q.unit.angle != angle)
        throw std::invalid_argument(context + ": " + kind + " is " +
                                    (angle ? "an angle" : "a length") + " but '" + q.unit_name +
                                    "' is not");
      const double v = q.unit.angle ? q.in(parse_unit("urad")) : q.in(parse_unit("um"));
      if (!(v > 0) || !std::isfinite(v))
        throw std::invalid_argument(context + ": the noise must be > 0");
      for (std::size_t i = 0; i < kObservationKinds; ++i) {
        const bool is_angle = std::string(observation_unit(i)) == "µrad";
        if (k == i || (k == kObservationKinds && is_angle == q.unit.angle)) base[i] = v;
      }
    }
  }
  return base;
}

void PlanOptions::validate() const {
  if (budget_s > 0) {
    if (units > 0 || target_sd_um > 0)
      throw std::invalid_argument(
          "--time-budget chooses the number of units: give it without --poses and --target-sd");
  } else {
    if (units == 0 && !(target_sd_um > 0))
      throw std::invalid_argument("give --poses N or --target-sd (e.g. --poses 64)");
    if (units > 0 && target_sd_um > 0)
      throw std::invalid_argument("--poses and --target-sd: give one of them");
  }
  if (budget_s < 0 || !std::isfinite(budget_s))
    throw std::invalid_argument("--time-budget must be > 0");
  if (restarts < 1 || restarts > 1000) throw std::invalid_argument("--restarts must be 1 to 1000");
  if (bound_iterations > 100000) throw std::invalid_argument("--bound must be 0 to 100000");
  if (random_sets < 1 || random_sets > 100000)
    throw std::invalid_argument("--random-sets must be 1 to 100000");
  if (!(rank_tolerance > 0 && rank_tolerance < 1))
    throw std::invalid_argument("--rank-tol must be in (0, 1)");
}

Planner::Planner(PlanOptions options) : options_(std::move(options)) { options_.validate(); }

namespace {

using namespace plan_detail;

// The steps of Planner::run, in order; each fills its part of the result.
class PlanSteps {
 public:
  PlanSteps(Context& cx, PlanResult& R)
      : cx_(cx), R_(R), in_(cx.in), o_(cx.o), d_(cx.in.model->description()) {
    what_ = in_.instrument == Instrument::Ballbar  ? "circles"
            : in_.instrument == Instrument::Line6d ? "positions"
                                                   : "poses";
  }

  // The volumetric prediction grid, what every candidate determines, the exchange's frame, the
  // fewest units that can reach the rank.
  void prepare() {
    Context& cx = cx_;
    PlanResult& R = R_;
    const PlanInput& in = in_;
    const PlanOptions& o = o_;
    const Description& d = d_;
    const std::vector<std::size_t>& cols = cx.cols;
    all_.resize(in.candidates.units.size());
    std::iota(all_.begin(), all_.end(), 0);
    // The volumetric prediction grid.
    {
      const PointData g = prediction_grid(d);
      const MatrixXd G = design_matrix(*in.model, *in.param, g);
      MatrixXd Gf(G.rows(), static_cast<Eigen::Index>(cols.size()));
      for (std::size_t q = 0; q < cols.size(); ++q)
        Gf.col(static_cast<Eigen::Index>(q)) = G.col(static_cast<Eigen::Index>(cols[q]));
      cx.Wg = Gf.transpose() * Gf / static_cast<double>(G.rows());
    }
    // Every candidate at once: what identify would determine from all of them.
    {
      EquilibratedSvd all_svd(MatrixXd::Zero(1, 1), 0.5, false);
      const LayoutFigures every =
          evaluate(cx, "every candidate", in.candidates.units, nullptr, &all_svd, nullptr, false);
      R.candidate_rank = every.rank;
      R.unidentifiable = null_combinations(all_svd, cols);
    }
    // The frame from every candidate: at most identify's rank and the set-up references'.
    const std::vector<MatrixXd> blocks = cx.model.blocks(in.candidates.units, true);
    cx.frame = make_frame(blocks, o.rank_tolerance,
                          static_cast<Eigen::Index>(R.candidate_rank + cx.model.nuisance()));
    {
      const Eigen::Index w = cx.frame.scale.size(), nf = static_cast<Eigen::Index>(cols.size());
      MatrixXd Wfull = MatrixXd::Zero(w, w);
      Wfull.topLeftCorner(nf, nf) = cx.Wg;
      const VectorXd inv = cx.frame.scale.cwiseInverse();
      // Prediction rows are θ rows: in the frame's scaled coordinates they are g·S⁻¹... the
      // weight of φ = S θ is S⁻¹ Wg S⁻¹.
      const MatrixXd Ws = inv.asDiagonal() * Wfull * inv.asDiagonal();
      cx.frame.W = cx.frame.Q.transpose() * Ws * cx.frame.Q;
    }
    r_ = cx.frame.Q.cols();
    for (const MatrixXd& z : cx.frame.Z)
      widest_ = std::max<std::size_t>(widest_, static_cast<std::size_t>(z.rows()));
    R.minimum_units = std::max<std::size_t>(in.candidates.forced.size(),
                                            (static_cast<std::size_t>(r_) + widest_ - 1) / widest_);
    R.greedy_units = greedy_rank_units(cx.frame, in.candidates.forced);
  }

  // --poses N.
  void plan_count() {
    check_size(o_.units, "--poses");
    R_.plan = plan_of(o_.units);
  }

  // --target-sd: the fewest units whose plan reaches the target.
  void plan_target() {
    Context& cx = cx_;
    PlanResult& R = R_;
    const PlanOptions& o = o_;
    const std::vector<std::size_t>& all = all_;
    const char* what = what_;
    const std::size_t candidates = in_.candidates.units.size();
    // The fewest units whose plan reaches the target: the candidates' own figure first (no
    // plan of fewer can do better), then upward from the minimum and a bisection.
    const LayoutFigures every = evaluate_candidates(cx, "every candidate", all);
    if (every.prediction_sd_um > o.target_sd_um)
      throw std::invalid_argument("--target-sd " + format_significant(o.target_sd_um, 3) +
                                  " um: even all " + std::to_string(candidates) + " candidate " +
                                  what + " give " + format_significant(every.prediction_sd_um, 3) +
                                  " um (lower the noise, or give more candidates)");
    // From the size the sequential design reaches full rank at: below it the exchange rarely
    // does, and a rank-deficient search is slow.
    std::size_t lo = std::max({R.minimum_units, R.greedy_units, std::size_t{1}}), hi = candidates;
    std::map<std::size_t, LayoutFigures> seen;
    std::set<std::size_t> planned;
    std::size_t last_planned = 0;
    auto sd_at = [&](std::size_t n) {
      auto it = seen.find(n);
      if (it == seen.end()) {
        it = seen.emplace(n, plan_of(n)).first;
        planned.insert(n);
        last_planned = n;
        if (it->second.rank < R.candidate_rank) it->second.prediction_sd_um = INFINITY;
        R.target_search.emplace_back(n, it->second.prediction_sd_um);
      }
      return it->second.prediction_sd_um;
    };
    seen.emplace(hi, every);
    // Upward from the minimum, each step to where sd ∝ 1/√n puts the target (at least half as
    // many again while the size misses the rank), then a bisection of the last step.
    for (std::size_t at = lo;;) {
      const double s = sd_at(at);
      if (s <= o.target_sd_um) {
        hi = at;
        break;
      }
      lo = at;
      const double next = std::isfinite(s)
                              ? std::ceil(static_cast<double>(at) * (s / o.target_sd_um) *
                                          (s / o.target_sd_um) * 1.05)
                              : std::ceil(static_cast<double>(at) * 1.5);
      at = std::min(candidates, std::max(at + 1, static_cast<std::size_t>(next)));
      if (at == candidates) break;
    }
    // Between the last miss and the first hit: where sd ∝ n^-α through both puts the target,
    // every other step a plain bisection (so that the interval always halves in two steps).
    for (bool model = true; hi > lo + 1; model = !model) {
      std::size_t mid = lo + (hi - lo) / 2;
      const double s_lo = seen.at(lo).prediction_sd_um, s_hi = seen.at(hi).prediction_sd_um;
      if (model && std::isfinite(s_lo) && s_hi > 0) {
        const double alpha =
            std::log(s_lo / s_hi) / std::log(static_cast<double>(hi) / static_cast<double>(lo));
        const double n = static_cast<double>(lo) * std::pow(s_lo / o.target_sd_um, 1 / alpha);
        if (alpha > 0 && std::isfinite(n))
          mid = std::clamp(static_cast<std::size_t>(std::ceil(n)), lo + 1, hi - 1);
      }
      if (sd_at(mid) <= o.target_sd_um)
        hi = mid;
      else
        lo = mid;
    }
    // The exchange's record of the size chosen (the last one planned may be another).
    if (hi == candidates && !planned.count(hi)) {
      R.plan = evaluate_candidates(cx, "plan", all);
      R.exchange = ExchangeResult{};
      R.exchange.selected = all;
    } else {
      if (last_planned != hi) plan_of(hi);
      R.plan = seen.at(hi);
    }
    R.plan.name = "plan";
  }

  // Count and target modes plan the candidates' full rank.
  void check_rank() const {
    const PlanResult& R = R_;
    if (R.plan.rank < R.candidate_rank)
      throw std::invalid_argument(
          "--poses: the " + std::to_string(R.plan.units.size()) + " planned " + what_ +
          " reach rank " + std::to_string(R.plan.rank) + " of the candidates' " +
          std::to_string(R.candidate_rank) + "; the sequential design reaches full rank with " +
          std::to_string(R.greedy_units));
  }

  // --bound: the continuous design's bound for the plan's size.
  void add_bound() {
    Context& cx = cx_;
    PlanResult& R = R_;
    const PlanOptions& o = o_;
    const std::size_t n = R.plan.units.size();
    const Eigen::Index r = r_;
    DesignProblem p;
    p.units = cx.frame.Z;
    p.weight = cx.frame.W;
    const auto rr = static_cast<std::size_t>(r);
    const ContinuousBound bi =
        continuous_design(p, DesignCriterion::I, o.bound_iterations, o.threads);
    R.prediction_sd_bound_um = std::sqrt(std::max(0.0, bi.for_units(n, DesignCriterion::I, rr)));
    R.criterion_bound = o.criterion == DesignCriterion::I
                            ? bi.for_units(n, o.criterion, rr)
                            : continuous_design(p, o.criterion, o.bound_iterations, o.threads)
                                  .for_units(n, o.criterion, rr);
    R.bound_iterations = o.bound_iterations;
  }

  // The regular layout and the best of the random sets, of the plan's size.
  void add_comparisons() {
    Context& cx = cx_;
    PlanResult& R = R_;
    const PlanInput& in = in_;
    const PlanOptions& o = o_;
    const std::vector<std::size_t>& all = all_;
    const std::size_t n = R.plan.units.size();
    std::string name;
    const std::vector<PlanUnit> grid = regular_layout(in, n, name, o.seed);
    R.compare.push_back(evaluate(cx, name, grid, nullptr));
    // The random sets, in parallel (each its own stream); the best by prediction_sd_um.
    std::vector<LayoutFigures> sets(o.random_sets);
    std::vector<std::vector<std::size_t>> picks(o.random_sets);
    for (std::size_t s = 0; s < o.random_sets; ++s) {
      std::uint64_t state = mix(o.seed * 0x9E3779B97F4A7C15ull + 7777 + s);
      std::vector<std::size_t> pool = all;
      for (std::size_t i = 0; i < n; ++i) {
        state = mix(state + 0x9E3779B97F4A7C15ull);
        const std::size_t k = i + static_cast<std::size_t>(state % (pool.size() - i));
        std::swap(pool[i], pool[k]);
      }
      picks[s].assign(pool.begin(), pool.begin() + static_cast<std::ptrdiff_t>(n));
      std::sort(picks[s].begin(), picks[s].end());
    }
    parallel_blocks(o.random_sets, 1, o.threads,
                    [&](std::size_t s, std::size_t, std::size_t, unsigned) {
                      sets[s] = evaluate_candidates(cx, "random", picks[s]);
                    });
    std::size_t best = 0;
    for (std::size_t s = 0; s < sets.size(); ++s) {
      R.random_sd_um.push_back(sets[s].prediction_sd_um);
      if (sets[s].prediction_sd_um < sets[best].prediction_sd_um) best = s;
    }
    sets[best].name = "best of " + std::to_string(o.random_sets) + " random";
    R.compare.push_back(sets[best]);
    for (LayoutFigures& f : R.compare)
      f.lost = R.candidate_rank > f.rank ? R.candidate_rank - f.rank : 0;
  }

  // The prediction SD map of the plan over two axes (the first two linear ones, else the first
  // two), the others at the middle of their travel.
  void add_sd_map() {
    Context& cx = cx_;
    PlanResult& R = R_;
    const PlanInput& in = in_;
    const Description& d = d_;
    const std::vector<std::size_t>& cols = cx.cols;
    MatrixXd cov;
    evaluate(cx, "plan", R.plan.layout, nullptr, nullptr, &cov);
    std::vector<std::size_t> axes;
    for (std::size_t a = 0; a < d.axes().size(); ++a)
      if (d.axis_joint(a).type == JointType::Prismatic && d.axis_joint(a).max > d.axis_joint(a).min)
        axes.push_back(a);
    for (std::size_t a = 0; a < d.axes().size() && axes.size() < 2; ++a)
      if (std::find(axes.begin(), axes.end(), a) == axes.end()) axes.push_back(a);
    SdMap& map = R.sd_map;
    PointData g;
    std::vector<double> middle;
    for (std::size_t a = 0; a < d.axes().size(); ++a) {
      const Joint& j = d.axis_joint(a);
      middle.push_back(j.max > j.min ? (j.min + j.max) / 2 : 0.0);
    }
    auto levels = [&](std::size_t a) {
      const Joint& j = d.axis_joint(a);
      std::vector<double> v;
      for (int i = 0; i < 21; ++i)
        v.push_back(j.max > j.min ? j.min + (j.max - j.min) * i / 20.0 : 0.0);
      return v;
    };
    map.x_axis = d.axis_joint(axes[0]).coordinate;
    map.x_unit = d.axis_joint(axes[0]).unit;
    map.x = levels(axes[0]);
    if (axes.size() > 1) {
      map.y_axis = d.axis_joint(axes[1]).coordinate;
      map.y_unit = d.axis_joint(axes[1]).unit;
      map.y = levels(axes[1]);
    } else {
      map.y = {0.0};
    }
    std::vector<std::vector<double>> poses;
    for (double y : map.y)
      for (double x : map.x) {
        poses.push_back(middle);
        poses.back()[axes[0]] = x;
        if (axes.size() > 1) poses.back()[axes[1]] = y;
      }
    g = volumetric_rows(std::move(poses));
    const MatrixXd G = design_matrix(*in.model, *in.param, g);
    MatrixXd Gf(G.rows(), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t q = 0; q < cols.size(); ++q)
      Gf.col(static_cast<Eigen::Index>(q)) = G.col(static_cast<Eigen::Index>(cols[q]));
    const VectorXd var = (Gf * cov).cwiseProduct(Gf).rowwise().sum();
    for (Eigen::Index p = 0; p + 2 < var.size(); p += 3)
      map.sd_um.push_back(std::sqrt(std::max(0.0, (var[p] + var[p + 1] + var[p + 2]) / 3)));
    map.middle = middle;
  }

 private:
  LayoutFigures plan_of(std::size_t n) {
    DesignProblem p;
    p.units = cx_.frame.Z;
    p.weight = cx_.frame.W;
    p.forced = in_.candidates.forced;
    ExchangeOptions eo;
    eo.criterion = o_.criterion;
    eo.size = n;
    eo.restarts = o_.restarts;
    eo.seed = o_.seed;
    eo.threads = o_.threads;
    R_.exchange = ExchangeDesign(eo).run(p);
    return evaluate_candidates(cx_, "plan", R_.exchange.selected);
  }

  void check_size(std::size_t n, const std::string& flag) const {
    const std::size_t candidates = in_.candidates.units.size();
    if (n < R_.minimum_units)
      throw std::invalid_argument(
          flag + ": " + std::to_string(n) + " " + what_ + " cannot determine the " +
          std::to_string(r_) + " combinations the candidates identify (at most " +
          std::to_string(widest_) + " per unit): at least " + std::to_string(R_.minimum_units) +
          " are needed, and the sequential design reaches full rank with " +
          std::to_string(R_.greedy_units));
    if (n > candidates)
      throw std::invalid_argument(flag + ": " + std::to_string(n) + " " + what_ + " but only " +
                                  std::to_string(candidates) +
                                  " candidates (give more with --candidates)");
  }

  Context& cx_;
  PlanResult& R_;
  const PlanInput& in_;
  const PlanOptions& o_;
  const Description& d_;
  const char* what_ = "poses";
  std::vector<std::size_t> all_;  // every candidate's index
  std::size_t widest_ = 1;        // the most rows of one unit
  Eigen::Index r_ = 0;            // the frame's rank
};

// The free parameters: identify's --fix.
std::vector<std::size_t> free_columns(const PlanInput& in, const PlanOptions& o) {
  const Description& d = in.model->description();
  std::vector<bool> fixed(in.param->size(), false);
  for (const std::string& f : o.fixed)
    for (const ErrorTarget& t : select_errors(d, f, "--fix " + quoted(f)))
      for (std::size_t p = 0; p < in.param->size(); ++p)
        if (in.param->parameters()[p].error == static_cast<int>(t.error)) fixed[p] = true;
  std::vector<std::size_t> cols;
  for (std::size_t p = 0; p < in.param->size(); ++p)
    if (!fixed[p]) cols.push_back(p);
  if (cols.empty()) throw std::invalid_argument("--fix: every error is fixed: nothing to plan");
  return cols;
}

}  // namespace

PlanResult Planner::run(const PlanInput& in) const {
  const auto t0 = std::chrono::steady_clock::now();
  const PlanOptions& o = options_;
  PlanResult R;
  R.instrument = in.instrument;
  R.instruments = in.instruments;
  R.candidates = in.candidates;
  R.noise = in.noise;
  Context cx(in, o, free_columns(in, o));
  R.free_parameters = cx.cols.size();
  PlanSteps steps(cx, R);
  steps.prepare();
  if (o.target_sd_um > 0) {
    steps.plan_target();
  } else if (o.budget_s > 0) {
    plan_budget(cx, R);  // plan_budget.cpp
  } else {
    steps.plan_count();
  }
  if (!(o.budget_s > 0)) steps.check_rank();
  R.plan.lost = R.candidate_rank - R.plan.rank;
  if (o.bound_iterations > 0) steps.add_bound();
  if (o.compare && !(o.budget_s > 0)) steps.add_comparisons();
  steps.add_sd_map();
  R.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return R;
}

}  // namespace weilgen
