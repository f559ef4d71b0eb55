// The instruments of `weilgen plan` (docs/planning.md, "Instruments"): their candidate units on a
// machine, and the measurement templates identify reads once filled.
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/analysis/plan.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/measure/line6d.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace weilgen {

namespace {

bool full_turn(const Joint& j) {
  return j.type == JointType::Revolute && (j.max - j.min) * j.to_base >= 2 * kPi - 1e-9;
}

// n values over the joint's travel: evenly from min to max; over one turn from min without the
// repeated end (min + 360° is min again) on a rotary axis that turns fully.
std::vector<double> travel_levels(const Joint& j, std::size_t n) {
  if (!(j.max > j.min)) return {0.0};
  if (n <= 1) return {(j.min + j.max) / 2};
  std::vector<double> v(n);
  if (full_turn(j)) {
    const double turn = 2 * kPi / j.to_base;
    for (std::size_t i = 0; i < n; ++i)
      v[i] = j.min + turn * static_cast<double>(i) / static_cast<double>(n);
  } else {
    for (std::size_t i = 0; i < n; ++i)
      v[i] = i + 1 == n
                 ? j.max
                 : j.min + (j.max - j.min) * static_cast<double>(i) / static_cast<double>(n - 1);
  }
  return v;
}

// Levels per axis so that a grid over k axes has about 4000 poses (3 to 41 per axis).
std::size_t default_levels(std::size_t k) {
  if (k == 0) return 1;
  const double n = std::floor(std::pow(4000.0, 1.0 / static_cast<double>(k)) + 1e-9);
  return static_cast<std::size_t>(std::clamp(n, 3.0, 41.0));
}

// The middle of an axis's travel, or 0 when it has none or 0 is within it and it is rotary.
double rest_value(const Joint& j) {
  if (!(j.max > j.min)) return 0;
  if (j.type == JointType::Revolute && j.min <= 0 && 0 <= j.max) return 0;
  return (j.min + j.max) / 2;
}

std::string pose_text(const Description& d, const std::vector<double>& pose) {
  std::string s;
  for (std::size_t a = 0; a < pose.size(); ++a)
    s += (a ? ", " : "") + d.axis_joint(a).coordinate + "=" + format_number(pose[a]);
  return s;
}

// The Cartesian product of per-axis values (axes order, the last axis fastest).
std::vector<std::vector<double>> product(const std::vector<std::vector<double>>& levels) {
  std::vector<std::vector<double>> out(1);
  for (const std::vector<double>& lv : levels) {
    std::vector<std::vector<double>> next;
    next.reserve(out.size() * lv.size());
    for (const auto& p : out)
      for (double v : lv) {
        next.push_back(p);
        next.back().push_back(v);
      }
    out = std::move(next);
  }
  return out;
}

struct Levels {
  std::vector<std::optional<double>> fixed;               // --set
  std::vector<std::optional<std::vector<double>>> named;  // --candidates
};

Levels parse_levels(const Description& d, const CandidateSpec& spec) {
  const std::size_t na = d.axes().size();
  Levels L;
  L.fixed.resize(na);
  L.named.resize(na);
  for (const std::string& item : spec.set) {
    for (auto& [a, values] : parse_axis_values(d, "--set", item)) {
      if (values.size() != 1)
        throw std::invalid_argument("--set: " + quoted(item) + ": " + d.axis_joint(a).coordinate +
                                    " takes one value (--set holds an axis; ranges go in "
                                    "--candidates)");
      if (L.fixed[a])
        throw std::invalid_argument("--set: axis " + d.axis_joint(a).coordinate +
                                    " is given twice");
      L.fixed[a] = values.front();
    }
  }
  for (const std::string& item : spec.grid) {
    for (auto& [a, values] : parse_axis_values(d, "--candidates", item)) {
      if (L.named[a])
        throw std::invalid_argument("--candidates: axis " + d.axis_joint(a).coordinate +
                                    " is given twice");
      if (L.fixed[a])
        throw std::invalid_argument("--candidates: axis " + d.axis_joint(a).coordinate +
                                    " is held by --set; give it in one of them");
      L.named[a] = std::move(values);
    }
  }
  return L;
}

// The candidate CSV (--candidates FILE): one pose per row, every coordinate a column.
std::vector<std::vector<double>> read_pose_file(const Description& d, const std::string& path,
                                                const std::string& flag) {
  ReadOptions ro = machine_read_options(d, true);
  const MeasurementTable t = read_measurements(path, ro);
  std::vector<std::vector<double>> poses(t.rows(), std::vector<double>(d.axes().size()));
  for (std::size_t a = 0; a < d.axes().size(); ++a) {
    const std::string& c = d.axis_joint(a).coordinate;
    if (!t.has(c))
      throw InputError(SourceLoc{path, t.header_line, 0}, flag + ": missing column '" + c +
                                                              "' (a pose needs every coordinate; " +
                                                              "columns: " + join(t.columns) + ")");
    const std::vector<double>& v = t.column(c);
    for (std::size_t r = 0; r < t.rows(); ++r) {
      if (!std::isfinite(v[r]))
        throw InputError(t.cell(r, c), flag + ": column '" + c + "' is empty");
      poses[r][a] = v[r];
    }
  }
  if (poses.empty()) throw InputError(SourceLoc{path, 0, 0}, flag + ": no poses");
  return poses;
}

bool in_travel(const Description& d, const std::vector<double>& pose) {
  for (std::size_t a = 0; a < pose.size(); ++a) {
    const Joint& j = d.axis_joint(a);
    if (!(j.max > j.min)) continue;
    const double slack = 1e-9 * std::max({1.0, std::abs(j.min), std::abs(j.max)});
    if (pose[a] < j.min - slack || pose[a] > j.max + slack) return false;
  }
  return true;
}

// ---- points ----------------------------------------------------------------------------------

void points_candidates(const Description& d, const CandidateSpec& spec, const Levels& L,
                       PlanCandidates& c) {
  PlanSetup s;
  s.instrument = Instrument::Points;
  s.tag = "points";
  s.what = "points (dx, dy, dz of the tool point)";
  c.setups.push_back(s);
  const std::size_t na = d.axes().size();
  std::vector<std::vector<double>> poses;
  if (!spec.file.empty()) {
    poses = read_pose_file(d, spec.file, "--candidates " + spec.file);
  } else {
    std::size_t free = 0;
    for (std::size_t a = 0; a < na; ++a) free += !L.fixed[a] && !L.named[a] ? 1 : 0;
    std::vector<std::vector<double>> levels;
    for (std::size_t a = 0; a < na; ++a)
      levels.push_back(L.fixed[a]   ? std::vector<double>{*L.fixed[a]}
                       : L.named[a] ? *L.named[a]
                                    : travel_levels(d.axis_joint(a), default_levels(free)));
    poses = product(levels);
  }
  for (auto& p : poses) c.units.push_back({0, std::move(p), 0});
}

// ---- rtest -----------------------------------------------------------------------------------

class NestSolver {
 public:
  NestSolver(const Model& model) : chain_(model.description()), d_(model.description()) {
    chain_.set_parameters(model.parameters());
    zero_.assign(d_.errors.size(), 0.0);
    for (std::size_t a = 0; a < d_.axes().size(); ++a)
      (d_.axis_joint(a).type == JointType::Prismatic ? linear_ : rotary_).push_back(a);
  }
  const std::vector<std::size_t>& linear() const { return linear_; }
  const std::vector<std::size_t>& rotary() const { return rotary_; }

  Eigen::Vector3d point(const std::vector<double>& q) const {
    return chain_.tool_in_workpiece(q, zero_).block<3, 1>(0, 3);
  }
  // The rank of d(tool point)/d(linear axes) at q.
  Eigen::Index linear_rank(const std::vector<double>& q) const {
    const Eigen::MatrixXd J = jacobian(q);
    return Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(J).setThreshold(1e-9).rank();
  }
  // Moves the linear axes of q so that the tool point is at `nest`; false when Newton does not
  // converge to 1 nm.
  bool solve(std::vector<double>& q, const Eigen::Vector3d& nest) const {
    for (int it = 0; it < 60; ++it) {
      const Eigen::Vector3d r = point(q) - nest;
      if (r.norm() < 1e-9) return true;
      const Eigen::VectorXd dq = jacobian(q).colPivHouseholderQr().solve(-r);
      for (std::size_t k = 0; k < linear_.size(); ++k)
        q[linear_[k]] += dq[static_cast<Eigen::Index>(k)];
    }
    return (point(q) - nest).norm() < 1e-9;
  }

 private:
  Eigen::MatrixXd jacobian(const std::vector<double>& q) const {
    const auto J = chain_.nominal_jacobian(q);
    Eigen::MatrixXd out(3, static_cast<Eigen::Index>(linear_.size()));
    for (std::size_t k = 0; k < linear_.size(); ++k)
      out.col(static_cast<Eigen::Index>(k)) =
          J.block(0, static_cast<Eigen::Index>(linear_[k]), 3, 1);
    return out;
  }
  NumericChain chain_;
  const Description& d_;
  std::vector<double> zero_;
  std::vector<std::size_t> linear_, rotary_;
};

void rtest_candidates(const Model& model, const CandidateSpec& spec, const Levels& L,
                      PlanCandidates& c) {
  const Description& d = model.description();
  const NestSolver solver(model);
  const std::size_t na = d.axes().size();
  std::vector<std::string> lin_names;
  for (std::size_t a : solver.linear()) lin_names.push_back(d.axis_joint(a).coordinate);
  if (solver.rotary().empty())
    throw std::invalid_argument(
        "--instrument rtest: the R-test measures while rotary axes turn; "
        "machine " +
        d.name + " has no rotary axis");
  if (solver.linear().size() < 3)
    throw std::invalid_argument(
        "--instrument rtest: holding the sphere at the nest while the rotary axes turn needs "
        "three linear axes; machine " +
        d.name + " has " + (lin_names.empty() ? std::string("none") : join(lin_names)));
  for (std::size_t a : solver.linear())
    if (L.named[a])
      throw std::invalid_argument("--candidates: " + d.axis_joint(a).coordinate +
                                  " is a linear axis: in an R-test the linear axes follow the nest "
                                  "(give the nest with --nest)");
  // The rotary levels (the candidates) and a coarse set of them (the default nest's search).
  std::size_t free = 0;
  for (std::size_t a : solver.rotary()) free += !L.fixed[a] && !L.named[a] ? 1 : 0;
  std::vector<std::vector<double>> levels, coarse;
  for (std::size_t a : solver.rotary()) {
    levels.push_back(L.fixed[a]   ? std::vector<double>{*L.fixed[a]}
                     : L.named[a] ? *L.named[a]
                                  : travel_levels(d.axis_joint(a), default_levels(free)));
    coarse.push_back(L.fixed[a] ? std::vector<double>{*L.fixed[a]}
                                : travel_levels(d.axis_joint(a), 7));
  }
  const std::vector<std::vector<double>> turns = product(levels);
  auto reachable = [&](const std::vector<double>& nest_pose,
                       const std::vector<std::vector<double>>& rot) {
    const Eigen::Vector3d p = solver.point(nest_pose);
    std::size_t n = 0;
    for (const std::vector<double>& t : rot) {
      std::vector<double> q = nest_pose;
      for (std::size_t i = 0; i < solver.rotary().size(); ++i) q[solver.rotary()[i]] = t[i];
      n += solver.solve(q, p) && in_travel(d, q) ? 1 : 0;
    }
    return n;
  };
  std::vector<double> rest(na);
  for (std::size_t a = 0; a < na; ++a)
    rest[a] = L.fixed[a] ? *L.fixed[a] : rest_value(d.axis_joint(a));
  // The nests: the linear axes where the sphere sits in the nest, every rotary axis at rest.
  // Without --nest: of a 5-level grid of the linear travel, the position from which the sphere
  // can be held at the most of a coarse grid of rotary poses (nearest the middle among equals).
  std::vector<std::string> nests = spec.nests;
  if (nests.empty()) {
    const std::vector<std::vector<double>> rot = product(coarse);
    std::vector<std::vector<double>> lin_levels;
    for (std::size_t a : solver.linear())
      lin_levels.push_back(L.fixed[a] ? std::vector<double>{*L.fixed[a]}
                                      : travel_levels(d.axis_joint(a), 5));
    std::size_t best_n = 0;
    double best_dist = INFINITY;
    std::vector<double> best = rest;
    for (const std::vector<double>& lv : product(lin_levels)) {
      std::vector<double> q = rest;
      double dist = 0;
      for (std::size_t i = 0; i < solver.linear().size(); ++i) {
        const std::size_t a = solver.linear()[i];
        q[a] = lv[i];
        const Joint& j = d.axis_joint(a);
        if (j.max > j.min) dist += std::pow((lv[i] - rest[a]) / (j.max - j.min), 2);
      }
      if (solver.linear_rank(q) < 3) continue;
      const std::size_t n = reachable(q, rot);
      if (n > best_n || (n == best_n && dist < best_dist)) best_n = n, best_dist = dist, best = q;
    }
    std::string text;
    for (std::size_t a : solver.linear())
      text += (text.empty() ? "" : ",") + d.axis_joint(a).coordinate + "=" + format_number(best[a]);
    nests.push_back(text);
  }
  for (std::size_t k = 0; k < nests.size(); ++k) {
    std::vector<double> pose = rest;
    if (!nests[k].empty())
      for (auto& [a, v] : parse_axis_values(d, "--nest", nests[k])) {
        if (v.size() != 1)
          throw std::invalid_argument("--nest: " + weilgen::quoted(nests[k]) +
                                      ": one value per axis");
        pose[a] = v.front();
      }
    if (solver.linear_rank(pose) < 3)
      throw std::invalid_argument("--instrument rtest: at the nest " + pose_text(d, pose) +
                                  " the linear axes " + join(lin_names) +
                                  " cannot move the tool point in three directions");
    PlanSetup s;
    s.instrument = Instrument::RTest;
    s.tag = nests.size() == 1 ? "rtest" : "rtest" + std::to_string(k + 1);
    s.nest_pose = pose;
    const Eigen::Vector3d p = solver.point(pose);
    s.nest_mm = {p[0], p[1], p[2]};
    s.what = "R-test, nest at " + pose_text(d, pose);
    c.setups.push_back(s);
  }
  for (std::size_t k = 0; k < c.setups.size(); ++k) {
    const Eigen::Vector3d nest(c.setups[k].nest_mm[0], c.setups[k].nest_mm[1],
                               c.setups[k].nest_mm[2]);
    for (const std::vector<double>& t : turns) {
      std::vector<double> q = c.setups[k].nest_pose;
      for (std::size_t i = 0; i < solver.rotary().size(); ++i) q[solver.rotary()[i]] = t[i];
      if (!solver.solve(q, nest) || !in_travel(d, q)) {
        ++c.dropped;
        continue;
      }
      c.units.push_back({k, q, 0});
    }
  }
}

// ---- ballbar ---------------------------------------------------------------------------------

void ballbar_candidates(const Model& model, const CandidateSpec& spec, const Levels& L,
                        PlanCandidates& c) {
  const Description& d = model.description();
  const BallbarMachine bm = ballbar_machine(model);
  const std::size_t na = d.axes().size();
  std::vector<std::size_t> linear;
  for (std::size_t a = 0; a < na; ++a)
    if (d.axis_joint(a).type == JointType::Prismatic) linear.push_back(a);
  if (linear.size() < 2)
    throw std::invalid_argument(
        "--instrument ballbar: a ballbar circle needs two linear axes; "
        "machine " +
        d.name + " has " + std::to_string(linear.size()));
  // The planes: --planes, else every pair of linear axes (XY, YZ, ZX for X, Y, Z).
  std::vector<std::pair<std::size_t, std::size_t>> planes;
  auto name_of = [&](std::size_t a) { return d.axis_joint(a).coordinate; };
  auto plane_text = [&](std::size_t a, std::size_t b) {
    return name_of(a).size() == 1 && name_of(b).size() == 1 ? name_of(a) + name_of(b)
                                                            : name_of(a) + "," + name_of(b);
  };
  if (!spec.planes.empty()) {
    for (const std::string& item : spec.planes) {
      // The plane alone: a tiny circle at the axes' rest values checks its axes.
      BallbarFlags f;
      f.plane = trim(item);
      f.radius = "1e-6 mm";
      std::vector<double> rest(na);
      for (std::size_t a = 0; a < na; ++a) rest[a] = rest_value(d.axis_joint(a));
      f.centre = pose_text(d, rest);
      const BallbarCircle circle = parse_ballbar_circle(f, bm);  // names --plane when bad
      std::size_t a1 = na, a2 = na;
      for (std::size_t a = 0; a < na; ++a) {
        if (name_of(a) == circle.first) a1 = a;
        if (name_of(a) == circle.second) a2 = a;
      }
      planes.emplace_back(a1, a2);
    }
  } else {
    // In name order (X, Y, Z), whatever the machine's axis order.
    std::stable_sort(linear.begin(), linear.end(),
                     [&](std::size_t x, std::size_t y) { return name_of(x) < name_of(y); });
    for (std::size_t i = 0; i < linear.size(); ++i)
      for (std::size_t k = i + 1; k < linear.size(); ++k) {
        // XY, YZ and ZX: each plane's first axis is the one before in the cycle.
        const bool wrap = linear.size() == 3 && i == 0 && k == 2;
        planes.emplace_back(wrap ? linear[k] : linear[i], wrap ? linear[i] : linear[k]);
      }
  }
  std::string refused;
  for (const auto& [a1, a2] : planes) {
    // Centre levels: in-plane axes where the circle fits, the others over their travel.
    std::vector<std::vector<double>> levels;
    bool fits = true;
    for (std::size_t a = 0; a < na; ++a) {
      const Joint& j = d.axis_joint(a);
      if (L.fixed[a]) {
        levels.push_back({*L.fixed[a]});
        continue;
      }
      const bool in_plane = a == a1 || a == a2;
      std::vector<double> lv;
      if (L.named[a]) {
        lv = *L.named[a];
      } else if (j.type == JointType::Prismatic) {
        Joint inner = j;
        if (in_plane && j.max > j.min) {
          const double r = spec.radius_mm / j.to_base;
          inner.min += r;
          inner.max -= r;
        }
        if (in_plane && j.max > j.min && !(inner.max >= inner.min)) {
          fits = false;
          break;
        }
        lv = inner.max > inner.min ? travel_levels(inner, 3) : std::vector<double>{inner.min};
      } else {
        lv = {rest_value(j)};
      }
      if (in_plane && j.max > j.min) {
        const double r = spec.radius_mm / j.to_base;
        std::vector<double> kept;
        for (double v : lv)
          if (v - r >= j.min - 1e-9 && v + r <= j.max + 1e-9) kept.push_back(v);
        lv = kept;
        if (lv.empty()) fits = false;
      }
      levels.push_back(lv);
    }
    const std::string plane = plane_text(a1, a2);
    if (!fits) {
      refused += (refused.empty() ? "" : "; ") + plane + ": a circle of radius " +
                 format_number(spec.radius_mm) + " mm does not fit the travel";
      continue;
    }
    for (const std::vector<double>& centre : product(levels)) {
      BallbarFlags f;
      f.plane = plane;
      f.radius = format_number(spec.radius_mm) + " mm";
      f.centre = pose_text(d, centre);
      BallbarCircle circle;
      try {
        circle = parse_ballbar_circle(f, bm);
        ballbar_directions(bm, circle, {0.0});
      } catch (const std::invalid_argument& e) {
        refused += (refused.empty() ? "" : "; ") + plane + ": " + e.what();
        break;
      }
      PlanSetup s;
      s.instrument = Instrument::Ballbar;
      s.circle = circle;
      s.tag = plane + "_" + std::to_string(c.setups.size() + 1);
      s.what = "ballbar " + plane + ", centre " + f.centre + ", radius " + f.radius;
      c.setups.push_back(s);
      c.units.push_back({c.setups.size() - 1, centre, 0});
    }
  }
  if (c.units.empty())
    throw std::invalid_argument("--instrument ballbar: no circle fits machine " + d.name + " (" +
                                refused + ")");
}

// ---- line6d ----------------------------------------------------------------------------------

void line6d_candidates(const Description& d, const Levels& L, PlanCandidates& c) {
  const std::size_t na = d.axes().size();
  std::vector<double> middle(na);
  for (std::size_t a = 0; a < na; ++a)
    middle[a] = L.fixed[a] ? *L.fixed[a] : rest_value(d.axis_joint(a));
  for (std::size_t a = 0; a < na; ++a) {
    const Joint& j = d.axis_joint(a);
    if (j.type != JointType::Prismatic ||
        (j.coordinate != "X" && j.coordinate != "Y" && j.coordinate != "Z"))
      continue;
    if (L.fixed[a]) continue;  // a held axis is not measured along
    PlanSetup s;
    s.instrument = Instrument::Line6d;
    s.axis = j.coordinate;
    s.tag = j.coordinate;
    for (const ChannelMapping& m : line6d_default_mapping(j.coordinate)) {
      const int k = d.error_index(m.iso);
      if (k >= 0 && d.errors[static_cast<std::size_t>(k)].body == d.axes()[a])
        s.channels.push_back(laser_column(m.channel));
    }
    if (s.channels.empty()) continue;
    s.what = "6D laser along " + j.coordinate + " (" + join(s.channels) + ")";
    c.setups.push_back(s);
    const std::vector<double> lv = L.named[a] ? *L.named[a] : travel_levels(j, 21);
    for (double v : lv) {
      std::vector<double> pose = middle;
      pose[a] = v;
      c.units.push_back({c.setups.size() - 1, pose, v * j.to_base});
    }
  }
  if (c.units.empty())
    throw std::invalid_argument("--instrument line6d: machine " + d.name +
                                " has no linear axis X, Y or Z with ISO errors of its own "
                                "(a 6D line file measures E_XK … E_CK of such an axis)");
}

// The units of an --include file for the instrument.
void include_file(const Model& model, const CandidateSpec& spec, const std::string& path,
                  PlanCandidates& c) {
  const Description& d = model.description();
  std::vector<std::vector<double>> poses = read_pose_file(d, path, "--include " + path);
  std::size_t setup = 0;
  if (spec.instrument == Instrument::RTest) {
    // The file's poses must hold the sphere at one of the nests.
    const NestSolver solver(model);
    const Eigen::Vector3d p = solver.point(poses.front());
    setup = c.setups.size();
    for (std::size_t k = 0; k < c.setups.size(); ++k)
      if ((p -
           Eigen::Vector3d(c.setups[k].nest_mm[0], c.setups[k].nest_mm[1], c.setups[k].nest_mm[2]))
              .norm() < 1e-6)
        setup = k;
    if (setup == c.setups.size())
      throw std::invalid_argument("--include " + path + ": its first pose puts the sphere at (" +
                                  format_number(p[0]) + ", " + format_number(p[1]) + ", " +
                                  format_number(p[2]) + ") mm, at no --nest");
  } else if (spec.instrument != Instrument::Points) {
    throw std::invalid_argument("--include: takes poses of points or rtest plans (" +
                                std::string(instrument_name(spec.instrument)) +
                                " set-ups are chosen with --candidates)");
  }
  for (auto& p : poses) {
    c.forced.push_back(c.units.size());
    c.units.push_back({setup, std::move(p), 0});
  }
}

MeasurementTable make_table(const std::string& file,
                            const std::vector<std::pair<std::string, std::string>>& keys,
                            const std::vector<std::string>& columns,
                            const std::vector<std::vector<double>>& values, const ReadOptions& ro) {
  MeasurementTable t;
  t.file = file;
  int line = 0;
  for (const auto& [k, v] : keys) {
    t.header_keys[k] = v;
    t.header_key_lines[k] = ++line;
  }
  t.header_line = ++line;
  t.columns = columns;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    t.info.push_back(classify_column(columns[i], ro));
    t.values[columns[i]] = values[i];
  }
  const std::size_t rows = values.empty() ? 0 : values.front().size();
  for (std::size_t r = 0; r < rows; ++r) t.lines.push_back(++line);
  return t;
}

}  // namespace

Instrument parse_instrument(const std::string& text, const std::string& flag) {
  const std::string t = lower(trim(text));
  if (t == "points") return Instrument::Points;
  if (t == "line6d") return Instrument::Line6d;
  if (t == "ballbar") return Instrument::Ballbar;
  if (t == "rtest" || t == "r-test") return Instrument::RTest;
  throw std::invalid_argument(flag + ": '" + text +
                              "' (expected points, line6d, ballbar or rtest)");
}

const char* instrument_name(Instrument i) {
  switch (i) {
    case Instrument::Points:
      return "points";
    case Instrument::Line6d:
      return "line6d";
    case Instrument::Ballbar:
      return "ballbar";
    case Instrument::RTest:
      return "rtest";
  }
  return "?";
}

std::vector<std::size_t> observed_kinds(Instrument i) {
  switch (i) {
    case Instrument::Points:
    case Instrument::RTest:
      return {0, 1, 2};
    case Instrument::Ballbar:
      return {static_cast<std::size_t>(kRadialOutput)};
    case Instrument::Line6d:
      return {static_cast<std::size_t>(kLinePositioning),
              static_cast<std::size_t>(kLineStraightness), static_cast<std::size_t>(kLineAngular)};
  }
  return {};
}

bool hold_nest(const Model& model, const PlanSetup& setup, std::vector<double>& pose) {
  const NestSolver solver(model);
  const Eigen::Vector3d nest(setup.nest_mm[0], setup.nest_mm[1], setup.nest_mm[2]);
  return solver.solve(pose, nest) && in_travel(model.description(), pose);
}

std::size_t rows_per_unit(Instrument instrument, const PlanSetup& setup, std::size_t angles) {
  switch (instrument) {
    case Instrument::Points:
    case Instrument::RTest:
      return 3;
    case Instrument::Ballbar:
      return angles;
    case Instrument::Line6d:
      return setup.channels.size();
  }
  return 0;
}

PlanCandidates plan_candidates(const Model& model, const CandidateSpec& spec) {
  const Description& d = model.description();
  const Levels L = parse_levels(d, spec);
  PlanCandidates c;
  if (!spec.file.empty() && spec.instrument != Instrument::Points)
    throw std::invalid_argument("--candidates FILE: a pose file is for --instrument points (" +
                                std::string(instrument_name(spec.instrument)) +
                                " candidates are grids: --candidates AXIS=start:stop:count)");
  switch (spec.instrument) {
    case Instrument::Points:
      points_candidates(d, spec, L, c);
      break;
    case Instrument::RTest:
      rtest_candidates(model, spec, L, c);
      break;
    case Instrument::Ballbar:
      ballbar_candidates(model, spec, L, c);
      break;
    case Instrument::Line6d:
      line6d_candidates(d, L, c);
      break;
  }
  if (spec.instrument == Instrument::Points) {
    std::vector<PlanUnit> kept;
    for (PlanUnit& u : c.units) {
      if (in_travel(d, u.pose))
        kept.push_back(std::move(u));
      else
        ++c.dropped;
    }
    c.units = std::move(kept);
  }
  for (const std::string& f : spec.include) include_file(model, spec, f, c);
  if (c.units.empty())
    throw std::invalid_argument("no candidate " + std::string(instrument_name(spec.instrument)) +
                                " units within the travel of machine " + d.name);
  return c;
}

std::vector<std::pair<std::string, MeasurementTable>> plan_tables(
    const Model& model, const PlanCandidates& c, const std::vector<PlanUnit>& units,
    std::size_t angles, bool fill) {
  const Description& d = model.description();
  const std::size_t na = d.axes().size();
  const ReadOptions points_ro = machine_read_options(d, false);
  ReadOptions line_ro = line6d_read_options();
  std::map<std::size_t, std::vector<const PlanUnit*>> by_setup;
  for (const PlanUnit& u : units) by_setup[u.setup].push_back(&u);
  const double out = fill ? 0.0 : kNaN;
  std::vector<std::pair<std::string, MeasurementTable>> tables;
  for (const auto& [k, list] : by_setup) {
    const PlanSetup& s = c.setups[k];
    std::vector<std::pair<std::string, std::string>> keys = {
        {"machine", d.name}, {"instrument", instrument_name(s.instrument)}};
    std::vector<std::string> cols;
    std::vector<std::vector<double>> v;
    auto column = [&](const std::string& name, std::vector<double> values) {
      cols.push_back(name);
      v.push_back(std::move(values));
    };
    const std::size_t n = list.size();
    if (s.instrument == Instrument::Points || s.instrument == Instrument::RTest) {
      if (s.instrument == Instrument::RTest) keys.emplace_back("nest", pose_text(d, s.nest_pose));
      for (std::size_t a = 0; a < na; ++a) {
        std::vector<double> x;
        for (const PlanUnit* u : list) x.push_back(u->pose[a]);
        column(d.axis_joint(a).coordinate, x);
      }
      std::vector<double> cyc(n, 1.0);
      column("cycle", cyc);
      column("t_s", std::vector<double>(n, kNaN));
      for (int o = 0; o < 3; ++o) column(kDeviationColumns[o], std::vector<double>(n, out));
      tables.emplace_back(s.tag, make_table(s.tag, keys, cols, v, points_ro));
    } else if (s.instrument == Instrument::Ballbar) {
      keys.emplace_back("plane", s.circle.plane);
      keys.emplace_back("centre", pose_text(d, list.front()->pose));
      keys.emplace_back("radius", format_number(s.circle.radius_mm) + " mm");
      keys.emplace_back("feed", "ccw");
      const std::vector<double> a = ballbar_angles(s.circle, angles);
      column("angle_deg", a);
      column("dr_um", std::vector<double>(a.size(), out));
      column("dir", std::vector<double>(a.size(), 1.0));
      column("cycle", std::vector<double>(a.size(), 1.0));
      column("t_s", std::vector<double>(a.size(), kNaN));
      tables.emplace_back(s.tag, make_table(s.tag, keys, cols, v, points_ro));
    } else {
      keys = {{"format", "line6d"}, {"axis", s.axis}, {"machine", d.name}};
      std::vector<std::size_t> order(n);
      for (std::size_t i = 0; i < n; ++i) order[i] = i;
      std::vector<double> x;
      for (const PlanUnit* u : list) {
        std::size_t a = 0;
        while (d.axis_joint(a).coordinate != s.axis) ++a;
        x.push_back(u->pose[a]);
      }
      column(s.axis, x);
      column("cycle", std::vector<double>(n, 1.0));
      column("t_s", std::vector<double>(n, kNaN));
      for (const std::string& ch : s.channels) column(ch, std::vector<double>(n, out));
      tables.emplace_back(s.tag, make_table(s.tag, keys, cols, v, line_ro));
    }
  }
  return tables;
}

PointData plan_observations(const Model& model, const PlanCandidates& c,
                            const std::vector<PlanUnit>& units, std::size_t angles,
                            std::vector<std::size_t>* unit_of_observation) {
  const Description& d = model.description();
  // Units in table order (grouped by set-up, as plan_tables writes them).
  std::map<std::size_t, std::vector<std::size_t>> by_setup;
  for (std::size_t i = 0; i < units.size(); ++i) by_setup[units[i].setup].push_back(i);
  std::vector<std::size_t> unit_of_row;
  for (const auto& [k, list] : by_setup) {
    const std::size_t per = c.setups[k].instrument == Instrument::Ballbar ? angles : 1;
    for (std::size_t i : list)
      for (std::size_t r = 0; r < per; ++r) unit_of_row.push_back(i);
  }
  PointData all;
  for (const auto& [tag, table] : plan_tables(model, c, units, angles, true))
    all.append(table_point_data(table, d, {}, model.parameters()));
  if (unit_of_observation) {
    unit_of_observation->clear();
    for (const PointObservation& ob : all.observations)
      unit_of_observation->push_back(unit_of_row[ob.row]);
  }
  return all;
}

}  // namespace weilgen
