// The measurement layouts of the truth generator (bench/gap/README.md, "Layouts"): volumetric
// grids (full, sparse, 60 points), ISO 230-2 line runs, ballbar circles in two planes, and
// R-test-like poses over the rotary axes of a five-axis machine.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "truth.hpp"

namespace weilgen::gapbench {

namespace {

struct LayoutName {
  const char* name;
  Layout::Kind kind;
};

const std::vector<LayoutName>& layout_table() {
  static const std::vector<LayoutName> table = {
      {"grid", Layout::Kind::Grid},       {"sparse", Layout::Kind::Sparse},
      {"small", Layout::Kind::Small},     {"line", Layout::Kind::Line},
      {"ballbar", Layout::Kind::Ballbar}, {"ballbar_yz", Layout::Kind::BallbarYz},
      {"rtest", Layout::Kind::Rtest},     {"rtest_small", Layout::Kind::RtestSmall}};
  return table;
}

}  // namespace

const std::vector<std::string>& layout_names() {
  static const std::vector<std::string> v = [] {
    std::vector<std::string> names;
    for (const LayoutName& l : layout_table()) names.push_back(l.name);
    return names;
  }();
  return v;
}

Layout Layout::parse(const std::string& name) {
  for (const LayoutName& l : layout_table())
    if (name == l.name) return Layout{l.kind};
  throw fail("unknown layout '" + name + "'");
}

std::vector<int> Synthesiser::linear_axes() const {
  std::vector<int> linear;
  for (std::size_t k = 0; k < axes_.size(); ++k)
    if (axes_[k].linear && axes_[k].max > axes_[k].min) linear.push_back(static_cast<int>(k));
  return linear;
}

void Synthesiser::add_pass(const std::vector<int>& sequence, int cycle, double dwell_s) {
  std::vector<int> dir(axes_.size(), 1);
  std::vector<double> prev;
  if (!rows_.empty()) {
    copy_to(dir, rows_.back().dir);
    copy_to(prev, rows_.back().axes);
  } else {
    copy_to(prev, poses_[static_cast<std::size_t>(sequence.front())]);
  }
  for (int p : sequence) {
    Row r;
    r.pose = p;
    copy_to(r.axes, poses_[static_cast<std::size_t>(p)]);
    for (std::size_t k = 0; k < axes_.size(); ++k)
      if (std::abs(r.axes[k] - prev[k]) > 1e-9) dir[k] = r.axes[k] > prev[k] ? 1 : -1;
    copy_to(prev, r.axes);
    copy_to(r.dir, dir);
    r.cycle = cycle;
    r.t_s = rows_.empty() ? 0.0 : rows_.back().t_s + dwell_s;
    rows_.push_back(std::move(r));
  }
}

void Synthesiser::build_layout(Rng& rng) {
  switch (layout_.kind) {
    case Layout::Kind::Grid:
      grid_layout(5, 11, 10, 3, 8);
      break;
    case Layout::Kind::Sparse:
      grid_layout(4, 6, 5, 2, 30);
      break;
    case Layout::Kind::Small:
      small_layout();
      break;
    case Layout::Kind::Line:
      line_layout(rng);
      break;
    case Layout::Kind::Ballbar:
      ballbar_layout(0, 1);
      break;
    case Layout::Kind::BallbarYz:
      ballbar_layout(1, 2);
      break;
    case Layout::Kind::Rtest:
    case Layout::Kind::RtestSmall:
      rtest_layout(layout_.kind == Layout::Kind::RtestSmall);
      break;
  }
  finish_layout();
}

// Volumetric grid (laser tracker): each linear axis gets 1 + round(per_travel * travel /
// longest travel) points clamped to [lo, hi], boustrophedon at every level; `cycles` passes,
// the even ones backwards, so every pose is approached from both sides.
void Synthesiser::grid_layout(int lo, int hi, double per_travel, int cycles, double dwell_s) {
  const std::vector<int> linear = linear_axes();
  if (linear.empty()) throw fail("the machine has no linear axis with a travel");
  double longest = 0;
  for (int k : linear) longest = std::max(longest, axes_[k].max - axes_[k].min);
  std::vector<int> n(axes_.size(), 1);
  grid_step_.assign(axes_.size(), 0.0);
  for (int k : linear) {
    const double travel = axes_[k].max - axes_[k].min;
    n[k] = std::clamp(1 + static_cast<int>(std::lround(per_travel * travel / longest)), lo, hi);
    grid_step_[k] = travel / (n[k] - 1);
  }
  std::vector<int> order = linear;  // outermost first: fewest points
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return n[a] < n[b]; });
  std::vector<double> home(axes_.size());
  for (std::size_t k = 0; k < axes_.size(); ++k) home[k] = axes_[k].home;
  std::vector<int> idx(axes_.size(), 0), starts(order.size(), 0), seq;
  auto rec = [&](auto&& self, std::size_t level) -> void {
    const int k = order[level];
    const bool back = starts[level]++ % 2 == 1;
    for (int j = 0; j < n[k]; ++j) {
      idx[k] = back ? n[k] - 1 - j : j;
      if (level + 1 == order.size()) {
        std::vector<double> p = home;
        for (int a : linear) p[a] = axes_[a].min + idx[a] * grid_step_[a];
        seq.push_back(static_cast<int>(poses_.size()));
        poses_.push_back(p);
      } else {
        self(self, level + 1);
      }
    }
  };
  rec(rec, 0);
  if (spec_.observations > 0) {  // the speed benchmark: as many cycles as needed (cut below)
    const std::size_t per_cycle = std::max<std::size_t>(1, seq.size() * linear.size());
    cycles = static_cast<int>(std::max<std::size_t>(
        1, (static_cast<std::size_t>(spec_.observations) + per_cycle - 1) / per_cycle));
  }
  for (int c = 1; c <= cycles; ++c) {
    std::vector<int> s = seq;
    if (c % 2 == 0) std::reverse(s.begin(), s.end());
    add_pass(s, c, dwell_s);
  }
  std::set<int> dims;
  for (int k : linear) dims.insert(axes_[k].dim);
  for (int d : dims) {
    columns_.push_back(std::string(kDimNames[d]) + "_um");
    column_dim_.push_back(d);
  }
}

// 60 points, one pass: 5, 4 and 3 positions on the linear axes by decreasing travel.
void Synthesiser::small_layout() {
  std::vector<int> linear = linear_axes();
  if (linear.size() < 3) throw fail("the small layout needs three linear axes");
  std::stable_sort(linear.begin(), linear.end(), [&](int a, int b) {
    return axes_[a].max - axes_[a].min > axes_[b].max - axes_[b].min;
  });
  const int counts[3] = {5, 4, 3};
  std::vector<int> n(axes_.size(), 1);
  grid_step_.assign(axes_.size(), 0.0);
  for (int i = 0; i < 3; ++i) {
    n[linear[i]] = counts[i];
    grid_step_[linear[i]] = (axes_[linear[i]].max - axes_[linear[i]].min) / (counts[i] - 1);
  }
  std::vector<double> home(axes_.size());
  for (std::size_t k = 0; k < axes_.size(); ++k) home[k] = axes_[k].home;
  std::vector<int> seq;
  int serp1 = 0;
  for (int i = 0; i < n[linear[2]]; ++i)
    for (int j0 = 0; j0 < n[linear[1]]; ++j0) {
      const int j = i % 2 ? n[linear[1]] - 1 - j0 : j0;
      const bool back = serp1++ % 2 == 1;
      for (int k0 = 0; k0 < n[linear[0]]; ++k0) {
        const int k = back ? n[linear[0]] - 1 - k0 : k0;
        std::vector<double> p = home;
        p[linear[2]] = axes_[linear[2]].min + i * grid_step_[linear[2]];
        p[linear[1]] = axes_[linear[1]].min + j * grid_step_[linear[1]];
        p[linear[0]] = axes_[linear[0]].min + k * grid_step_[linear[0]];
        seq.push_back(static_cast<int>(poses_.size()));
        poses_.push_back(p);
      }
    }
  add_pass(seq, 1, 60);
  std::set<int> dims;
  for (int k : linear) dims.insert(axes_[k].dim);
  for (int d : dims) {
    columns_.push_back(std::string(kDimNames[d]) + "_um");
    column_dim_.push_back(d);
  }
}

// ISO 230-2 bidirectional runs of one linear axis: 101 targets, 5 cycles, up then down; the other
// linear axes parked at random positions in the middle half of their travel, rotary axes at home.
void Synthesiser::line_layout(Rng& rng) {
  const std::vector<int> linear = linear_axes();
  if (linear.empty()) throw fail("the machine has no linear axis with a travel");
  line_axis_ = linear[static_cast<std::size_t>(rng.index(static_cast<int>(linear.size())))];
  std::vector<double> park(axes_.size());
  for (std::size_t k = 0; k < axes_.size(); ++k) park[k] = axes_[k].home;
  for (int k : linear) {
    const double travel = axes_[k].max - axes_[k].min;
    park[k] = std::round(rng.uniform(axes_[k].min + 0.25 * travel, axes_[k].max - 0.25 * travel));
  }
  constexpr int kTargets = 101, kCycles = 5;
  const double travel = axes_[line_axis_].max - axes_[line_axis_].min;
  for (int i = 0; i < kTargets; ++i) {
    std::vector<double> p = park;
    p[line_axis_] = axes_[line_axis_].min + travel * i / (kTargets - 1);
    poses_.push_back(p);
  }
  for (int c = 1; c <= kCycles; ++c)
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<int> s;
      for (int j = 0; j < kTargets; ++j) s.push_back(pass == 0 ? j : kTargets - 1 - j);
      const std::size_t first = rows_.size();
      add_pass(s, c, 15);
      for (std::size_t r = first; r < rows_.size(); ++r) {
        rows_[r].feed_dir = pass == 0 ? 1 : -1;
        rows_[r].dir.assign(axes_.size(), 1);
        rows_[r].dir[static_cast<std::size_t>(line_axis_)] = rows_[r].feed_dir;
      }
    }
  const int d = axes_[line_axis_].dim;
  columns_ = {std::string(kDimNames[d]) + "_um"};
  column_dim_ = {d};
}

// Ballbar (ISO 230-4) circles in the plane of the linear axes along dims (dim_a, dim_b): XY or
// YZ. Centre at mid-travel, radius 0.3 x the shorter travel (rounded down to 10 mm), 2 deg steps,
// ccw then cw, 6 cycles 30 min apart (a warm-up series). Rotary axes at home.
void Synthesiser::ballbar_layout(int dim_a, int dim_b) {
  const std::vector<int> linear = linear_axes();
  for (int k : linear) {
    if (axes_[k].dim == dim_a && plane_a_ < 0) plane_a_ = k;
    if (axes_[k].dim == dim_b && plane_b_ < 0) plane_b_ = k;
  }
  if (plane_a_ < 0 || plane_b_ < 0)
    throw fail("the ballbar layout needs linear axes along " + std::string(1, "xyz"[dim_a]) +
               " and " + std::string(1, "xyz"[dim_b]));
  centre_.resize(axes_.size());
  for (std::size_t k = 0; k < axes_.size(); ++k) centre_[k] = axes_[k].home;
  for (int k : linear) centre_[k] = std::round((axes_[k].min + axes_[k].max) / 2);
  const double ta = axes_[plane_a_].max - axes_[plane_a_].min;
  const double tb = axes_[plane_b_].max - axes_[plane_b_].min;
  radius_mm_ = 10 * std::floor(0.03 * std::min(ta, tb));
  constexpr int kPoints = 180, kCycles = 6;
  constexpr double kPointS = 0.25, kCycleS = 1800;
  for (int i = 0; i < kPoints; ++i) {
    const double th = 2.0 * i * kPi / 180;
    std::vector<double> p = centre_;
    p[plane_a_] += radius_mm_ * std::cos(th);
    p[plane_b_] += radius_mm_ * std::sin(th);
    poses_.push_back(p);
  }
  for (int c = 1; c <= kCycles; ++c) {
    double t = (c - 1) * kCycleS;
    for (int pass = 0; pass < 2; ++pass) {
      for (int j = 0; j < kPoints; ++j) {
        Row r;
        r.pose = pass == 0 ? j : (kPoints - j) % kPoints;
        copy_to(r.axes, poses_[static_cast<std::size_t>(r.pose)]);
        r.feed_dir = pass == 0 ? 1 : -1;
        r.angle_deg = 2.0 * r.pose;
        // Each axis' direction of motion just before the point (1 deg back along the feed).
        const double th = (r.angle_deg - r.feed_dir * 1.0) * kPi / 180;
        r.dir.assign(axes_.size(), 1);
        r.dir[static_cast<std::size_t>(plane_a_)] = -r.feed_dir * std::sin(th) > 0 ? 1 : -1;
        r.dir[static_cast<std::size_t>(plane_b_)] = r.feed_dir * std::cos(th) > 0 ? 1 : -1;
        r.cycle = c;
        r.t_s = t;
        t += kPointS;
        rows_.push_back(std::move(r));
      }
      t += 5;  // reversal of the feed
    }
  }
  const std::vector<double> zero(truth_desc_.errors.size(), 0.0);
  centre_point_ = tool_point(*truth_chain_, centre_, zero);
  columns_ = {"dr_um"};
  column_dim_ = {-1};
}

// R-test-like poses (ISO 10791-6): spheres fixed to the workpiece, the tool kept on each
// sphere's centre while the two rotary axes move (the linear axes follow by the nominal
// kinematics). The axis that turns a full revolution (C) takes 12 positions 30 deg apart, the
// tilting one (A or B) 5 levels; each tilt level sweeps C up, the next down, and the cycles run
// backwards in turn, so every pose is approached from both sides. The sensor nest reads the
// sphere's position relative to the tool: dx, dy, dz. `small`: one sphere, one pass (60 poses).
void Synthesiser::rtest_layout(bool small) {
  int turn = -1, tilt = -1;
  for (std::size_t k = 0; k < axes_.size(); ++k) {
    if (axes_[k].linear) continue;
    if (axes_[k].max - axes_[k].min >= 360 && turn < 0)
      turn = static_cast<int>(k);
    else if (tilt < 0)
      tilt = static_cast<int>(k);
  }
  if (turn < 0 || tilt < 0) throw fail("the rtest layout needs a turning and a tilting axis");
  const std::vector<int> linear = linear_axes();
  if (linear.size() != 3) throw fail("the rtest layout needs three linear axes");
  const std::vector<double> zero(truth_desc_.errors.size(), 0.0);
  std::vector<double> mid(axes_.size());
  for (std::size_t k = 0; k < axes_.size(); ++k)
    mid[k] = axes_[k].linear ? (axes_[k].min + axes_[k].max) / 2 : axes_[k].home;
  // The tool point at mid-travel with the rotary axes at home: the spheres sit around it.
  const Eigen::Vector3d p_home = tool_point(*truth_chain_, mid, zero);
  // The linear axes that put the nominal tool point on p (workpiece frame) with the rotary axes
  // at q: Newton on the (affine in the linear axes) chain; false when out of travel.
  auto solve = [&](std::vector<double>& q, const Eigen::Vector3d& p) {
    for (int it = 0; it < 6; ++it) {
      const Eigen::Vector3d f = tool_point(*truth_chain_, q, zero) - p;
      if (f.norm() < 1e-9) break;
      Eigen::Matrix3d J;
      for (int c = 0; c < 3; ++c) {
        std::vector<double> u = q, d = q;
        u[static_cast<std::size_t>(linear[c])] += 1;
        d[static_cast<std::size_t>(linear[c])] -= 1;
        J.col(c) = (tool_point(*truth_chain_, u, zero) - tool_point(*truth_chain_, d, zero)) / 2;
      }
      const Eigen::Vector3d step = J.fullPivLu().solve(f);
      for (int c = 0; c < 3; ++c) q[static_cast<std::size_t>(linear[c])] -= step[c];
    }
    if ((tool_point(*truth_chain_, q, zero) - p).norm() > 1e-6) return false;
    for (int k : linear)
      if (q[static_cast<std::size_t>(k)] < axes_[k].min - 1e-9 ||
          q[static_cast<std::size_t>(k)] > axes_[k].max + 1e-9)
        return false;
    return true;
  };
  std::vector<double> tilts;
  for (double t : {-60.0, -30.0, 0.0, 30.0, 60.0})
    if (t >= axes_[tilt].min && t <= axes_[tilt].max) tilts.push_back(t);
  std::vector<double> turns;
  for (int i = 0; i < 12; ++i) turns.push_back(30.0 * i);
  // Sphere candidates around p_home (in the plane across the turning axis and off it); a
  // sphere is kept when every pose is within travel, the tilts narrowed to +-30 if needed.
  const double offsets[][3] = {{120, 0, 0}, {0, 90, 40}, {-80, -60, 20}, {60, 60, 0}};
  const std::size_t want = small ? 1 : 2;
  for (int attempt = 0; attempt < 2 && spheres_.size() < want; ++attempt) {
    if (attempt == 1) {
      spheres_.clear();
      poses_.clear();
      tilts = {-30, -15, 0, 15, 30};
    }
    for (const auto& o : offsets) {
      if (spheres_.size() >= want) break;
      const Eigen::Vector3d p = p_home + Eigen::Vector3d(o[0], o[1], o[2]);
      bool ok = true;
      std::vector<std::vector<double>> ps;
      for (double a : tilts)
        for (double c : turns) {
          std::vector<double> q = mid;
          q[static_cast<std::size_t>(tilt)] = a;
          q[static_cast<std::size_t>(turn)] = c;
          ok = ok && solve(q, p);
          ps.push_back(q);
        }
      if (!ok) continue;
      spheres_.push_back({p[0], p[1], p[2]});
      for (auto& q : ps) poses_.push_back(q);
    }
  }
  if (spheres_.size() < want) throw fail("rtest: no sphere position within the axes' travel");
  const int per_tilt = static_cast<int>(turns.size());
  std::vector<int> seq;
  for (std::size_t s = 0; s < spheres_.size(); ++s)
    for (std::size_t a = 0; a < tilts.size(); ++a)
      for (int c0 = 0; c0 < per_tilt; ++c0) {
        const int c = a % 2 ? per_tilt - 1 - c0 : c0;
        seq.push_back(static_cast<int>((s * tilts.size() + a) * turns.size()) + c);
      }
  const int cycles = small ? 1 : 3;
  for (int c = 1; c <= cycles; ++c) {
    std::vector<int> s = seq;
    if (c % 2 == 0) std::reverse(s.begin(), s.end());
    add_pass(s, c, small ? 30 : 10);
  }
  grid_step_.assign(axes_.size(), 0.0);
  grid_step_[static_cast<std::size_t>(turn)] = 30;
  if (tilts.size() > 1) grid_step_[static_cast<std::size_t>(tilt)] = tilts[1] - tilts[0];
  for (int d = 0; d < 3; ++d) {
    columns_.push_back(std::string(kDimNames[d]) + "_um");
    column_dim_.push_back(d);
  }
}

void Synthesiser::finish_layout() {
  if (spec_.observations > 0)  // cut after the row that reaches that many observations
    rows_.resize(std::min(
        rows_.size(),
        (static_cast<std::size_t>(spec_.observations) + columns_.size() - 1) / columns_.size()));
  for (std::size_t r = 0; r < rows_.size(); ++r)
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      obs_row_.push_back(static_cast<int>(r));
      obs_col_.push_back(static_cast<int>(c));
    }
  t_total_s_ = rows_.back().t_s;
  // The lagged temperature rise on a fine grid (exact step response of the first-order lag for
  // an input held over each step).
  constexpr int kSteps = 20000;
  const double dt = t_total_s_ / kSteps, tau = t_total_s_ / 12;
  const double a = 1 - std::exp(-dt / tau);
  drift_table_.assign(kSteps + 1, 0.0);
  for (int i = 0; i < kSteps; ++i)
    drift_table_[i + 1] =
        drift_table_[i] + (temperature((i + 0.5) * dt) - 22.0 - drift_table_[i]) * a;
  truth_jacobians_.resize(poses_.size());
}

// Spindle warm-up to 3 K with time constant T/4, spindle off at 0.6 T, cooling with T/5: a
// profile that rises and falls, so a drift is not a monotone function of time.
double Synthesiser::temperature(double t_s) const {
  const double T = t_total_s_, t_off = 0.6 * T;
  auto warm = [&](double t) { return 3.0 * (1 - std::exp(-t / (T / 4))); };
  if (t_s <= t_off) return 22.0 + warm(t_s);
  return 22.0 + warm(t_off) * std::exp(-(t_s - t_off) / (T / 5));
}

double Synthesiser::drift(double t_s) const {
  const double x = std::clamp(t_s / t_total_s_, 0.0, 1.0) * (drift_table_.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), drift_table_.size() - 2);
  const double f = x - static_cast<double>(i);
  return drift_table_[i] * (1 - f) + drift_table_[i + 1] * f;
}

double Synthesiser::axis_step(int axis) const {
  if (layout_.line()) return (axes_[axis].max - axes_[axis].min) / 100;
  if (layout_.ballbar()) return radius_mm_ * 2 * kPi / 180;  // 2 deg of arc
  return grid_step_[static_cast<std::size_t>(axis)];
}

std::pair<double, double> Synthesiser::data_range(int axis) const {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& p : poses_) {
    lo = std::min(lo, p[static_cast<std::size_t>(axis)]);
    hi = std::max(hi, p[static_cast<std::size_t>(axis)]);
  }
  return {lo, hi};
}

std::size_t Synthesiser::distinct_positions(int axis) const {
  std::vector<double> v;
  for (const auto& p : poses_) v.push_back(p[static_cast<std::size_t>(axis)]);
  std::sort(v.begin(), v.end());
  std::size_t n = v.empty() ? 0 : 1;
  for (std::size_t i = 1; i < v.size(); ++i) n += v[i] > v[i - 1] + 1e-9;
  return n;
}

}  // namespace weilgen::gapbench
