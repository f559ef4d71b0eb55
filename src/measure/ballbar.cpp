#include "weilgen/measure/ballbar.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/uq/dense.hpp"

namespace weilgen {
namespace {

// Angles closer than this (deg) are the same point of the circle.
constexpr double kSameAngleDeg = 1e-9;

double rad(double deg) { return deg * kPi / 180.0; }

// [0, 360).
double wrap_deg(double a) {
  double w = std::fmod(a, 360.0);
  if (w < 0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

// ---- Settings: one header key or flag ---------------------------------------------------------

// Where a circle setting comes from and how to complain about it.
struct Setting {
  std::string key;  // "plane", "centre", "radius", "feed"
  std::string text;
  SourceLoc loc;
  bool flag = false;
  bool given = false;

  [[noreturn]] void fail(const std::string& why) const {
    if (flag) throw std::invalid_argument("--" + key + ": " + quoted(text) + ": " + why);
    throw InputError(loc, "ballbar: '# " + key + ": " + text + "': " + why);
  }
};

struct SettingSource {
  const std::map<std::string, std::string>* keys = nullptr;  // null: flags only
  const std::map<std::string, int>* key_lines = nullptr;
  std::string file;
  int header_line = 0;
};

Setting setting(const SettingSource& src, const std::string& key, const std::string& flag,
                const std::vector<std::string>& spellings) {
  Setting s;
  s.key = key;
  if (!trim(flag).empty()) {
    s.text = trim(flag);
    s.loc = SourceLoc{"--" + key, 0, 0};
    s.flag = s.given = true;
    return s;
  }
  if (!src.keys) return s;
  const std::string* found = nullptr;
  for (const std::string& k : spellings) {
    const auto it = src.keys->find(k);
    if (it == src.keys->end()) continue;
    const auto line = src.key_lines->find(k);
    const SourceLoc loc{src.file, line == src.key_lines->end() ? 0 : line->second, 0};
    if (found) {
      throw InputError(
          loc, "ballbar: '# " + k + ":' and '# " + *found + ":' are the same setting; give one");
    }
    found = &it->first;
    s.text = trim(it->second);
    s.loc = loc;
    s.given = true;
  }
  return s;
}

[[noreturn]] void missing(const SettingSource& src, const std::string& key, const std::string& what,
                          const std::string& example) {
  if (!src.keys) {
    throw std::invalid_argument("ballbar: --" + key + " is required (" + what + ", e.g. --" + key +
                                " " + quoted(example) + ")");
  }
  throw InputError(SourceLoc{src.file, src.header_line, 0},
                   "ballbar: the header key '# " + key + ":' is missing (" + what + ", e.g. '# " +
                       key + ": " + example + "'; or --" + key + ")");
}

int coordinate_index(const BallbarMachine& m, const std::string& name) {
  for (std::size_t i = 0; i < m.coordinates.size(); ++i) {
    if (m.coordinates[i] == name) return static_cast<int>(i);
  }
  return -1;
}

std::string coordinates_text(const BallbarMachine& m) {
  return "the machine's coordinates: " + (m.coordinates.empty() ? "none" : join(m.coordinates));
}

bool has_range(const BallbarMachine& m, std::size_t i) {
  return i < m.min.size() && i < m.max.size() && m.min[i] < m.max[i];
}

std::string range_text(const BallbarMachine& m, std::size_t i) {
  return "[" + format_number(m.min[i]) + ", " + format_number(m.max[i]) + "] " + m.units[i];
}

bool within_range(const BallbarMachine& m, std::size_t i, double v) {
  if (!has_range(m, i)) return true;
  const double slack = 1e-9 * std::max({1.0, std::abs(m.min[i]), std::abs(m.max[i])});
  return v >= m.min[i] - slack && v <= m.max[i] + slack;
}

void parse_plane(const Setting& s, const BallbarMachine& m, BallbarCircle& c) {
  const std::string t = s.text;
  std::vector<std::pair<std::string, std::string>> candidates;
  if (t.find_first_of(", \t") != std::string::npos) {
    std::vector<std::string> parts;
    std::string cur;
    for (char ch : t + ",") {
      if (ch == ',' || ch == ' ' || ch == '\t') {
        if (!cur.empty()) parts.push_back(cur);
        cur.clear();
      } else {
        cur += ch;
      }
    }
    if (parts.size() == 2) candidates.emplace_back(parts[0], parts[1]);
  } else {
    for (std::size_t k = 1; k < t.size(); ++k) {
      const std::string a = t.substr(0, k), b = t.substr(k);
      if (coordinate_index(m, a) >= 0 && coordinate_index(m, b) >= 0) candidates.emplace_back(a, b);
    }
  }
  if (candidates.size() > 1) {
    s.fail("ambiguous: write the two coordinates with a comma (e.g. " + candidates[0].first + "," +
           candidates[0].second + ")");
  }
  if (candidates.empty() || coordinate_index(m, candidates[0].first) < 0 ||
      coordinate_index(m, candidates[0].second) < 0) {
    s.fail("not two coordinates of the machine (" + coordinates_text(m) + "; e.g. XY)");
  }
  const auto& [first, second] = candidates[0];
  if (first == second) s.fail("the plane needs two distinct coordinates (e.g. XY)");
  for (const std::string& name : {first, second}) {
    if (!m.prismatic[static_cast<std::size_t>(coordinate_index(m, name))]) {
      s.fail(name + " is a rotary axis: a ballbar circle needs two linear axes");
    }
  }
  c.first = first;
  c.second = second;
  c.plane = first + second;
}

void parse_centre(const Setting& s, const BallbarMachine& m, BallbarCircle& c) {
  const char* const form = "NAME=value, ..., e.g. X=250, Y=0, Z=-100";
  std::vector<bool> named(m.coordinates.size(), false);
  for (const std::string& raw : split(s.text, ',')) {
    const std::string item = trim(raw);
    if (item.empty()) s.fail(std::string("empty item (expected ") + form + ")");
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) s.fail(quoted(item) + " is not NAME=value (" + form + ")");
    const std::string name = trim(item.substr(0, eq));
    const int index = coordinate_index(m, name);
    if (index < 0) s.fail("unknown coordinate '" + name + "' (" + coordinates_text(m) + ")");
    const auto i = static_cast<std::size_t>(index);
    if (named[i]) s.fail(name + " is given twice");
    named[i] = true;
    Quantity q;
    try {
      q = parse_quantity_unit(trim(item.substr(eq + 1)), m.units[i], name);
    } catch (const std::invalid_argument& e) {
      s.fail(e.what());
    }
    if (q.unit.angle == m.prismatic[i]) {
      s.fail(name + " is " + (m.prismatic[i] ? "a length" : "an angle") + " in " + m.units[i] +
             ", but \"" + q.unit_name + "\" is " + (q.unit.angle ? "an angle" : "a length") +
             " unit");
    }
    const double v = q.number * (q.unit.to_base / m.to_base[i]);
    if (!within_range(m, i, v)) {
      s.fail(name + " = " + format_number(v) + " " + m.units[i] + " is outside the axis range " +
             range_text(m, i));
    }
    c.centre[name] = v;
  }
  for (std::size_t i = 0; i < m.coordinates.size(); ++i) {
    if (named[i]) continue;
    if (!within_range(m, i, 0.0)) {
      s.fail(m.coordinates[i] + " is not given and 0 is outside its range " + range_text(m, i) +
             ": give a value (e.g. " + m.coordinates[i] + "=" +
             format_number(0.5 * (m.min[i] + m.max[i])) + ")");
    }
    c.centre[m.coordinates[i]] = 0.0;
  }
}

void parse_radius(const Setting& s, BallbarCircle& c) {
  Quantity q;
  try {
    q = parse_quantity_unit(s.text, "mm", "radius");
  } catch (const std::invalid_argument& e) {
    s.fail(e.what());
  }
  if (q.unit.angle) s.fail("the radius is a length, \"" + q.unit_name + "\" is an angle unit");
  if (!(q.value() > 0)) s.fail("the radius must be > 0");
  c.radius_mm = q.value();
}

void parse_feed(const Setting& s, BallbarCircle& c) {
  const std::string f = lower(s.text);
  if (f == "ccw") {
    c.feed = 1;
  } else if (f == "cw") {
    c.feed = -1;
  } else {
    s.fail("the feed is ccw (counter-clockwise, θ increasing) or cw");
  }
}

BallbarCircle parse_circle(const SettingSource& src, const BallbarMachine& m,
                           const BallbarFlags& flags) {
  if (m.prismatic.size() != m.coordinates.size() || m.units.size() != m.coordinates.size() ||
      m.to_base.size() != m.coordinates.size()) {
    throw std::invalid_argument("ballbar: BallbarMachine fields differ in size");
  }
  const Setting plane = setting(src, "plane", flags.plane, {"plane"});
  const Setting centre = setting(src, "centre", flags.centre, {"centre", "center"});
  const Setting radius = setting(src, "radius", flags.radius, {"radius"});
  const Setting feed = setting(src, "feed", flags.feed, {"feed"});
  if (!plane.given) missing(src, "plane", "the circle's plane", "XY");
  if (!centre.given) missing(src, "centre", "the circle's centre", "X=250, Y=0, Z=-100");
  if (!radius.given) missing(src, "radius", "the nominal radius", "150 mm");
  BallbarCircle c;
  parse_plane(plane, m, c);
  parse_centre(centre, m, c);
  parse_radius(radius, c);
  if (feed.given) parse_feed(feed, c);
  for (const Setting* s : {&plane, &centre, &radius, &feed}) {
    if (s->given) c.sources[s->key] = s->loc;
  }
  // The circle must stay within the travel of both in-plane axes.
  for (const std::string& name : {c.first, c.second}) {
    const auto i = static_cast<std::size_t>(coordinate_index(m, name));
    const double r = c.radius_mm / m.to_base[i];
    const double v = c.centre.at(name);
    if (!within_range(m, i, v - r) || !within_range(m, i, v + r)) {
      radius.fail("the circle leaves the range of " + name + " " + range_text(m, i) + ": " +
                  format_number(v) + " ± " + format_number(r) + " " + m.units[i]);
    }
  }
  return c;
}

// ---- Geometry --------------------------------------------------------------------------------

using V3 = std::array<double, 3>;

double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const V3& a) { return std::sqrt(dot(a, a)); }

// The letter rule's direction of a coordinate, or false.
bool letter_direction(const std::string& name, V3& e) {
  static const std::string kLetters[3] = {"XU", "YV", "ZW"};
  e = {0, 0, 0};
  if (name.size() != 1) return false;
  for (int k = 0; k < 3; ++k) {
    if (kLetters[k].find(name[0]) != std::string::npos) {
      e[static_cast<std::size_t>(k)] = 1;
      return true;
    }
  }
  return false;
}

// The in-plane indices of a circle, checked against the machine.
std::pair<std::size_t, std::size_t> plane_indices(const BallbarMachine& m, const BallbarCircle& c) {
  const int i1 = coordinate_index(m, c.first), i2 = coordinate_index(m, c.second);
  if (i1 < 0 || i2 < 0 || i1 == i2) {
    throw std::invalid_argument("ballbar: plane " + quoted(c.first + "," + c.second) +
                                " is not two distinct coordinates (" + coordinates_text(m) + ")");
  }
  for (int i : {i1, i2}) {
    if (!m.prismatic[static_cast<std::size_t>(i)]) {
      throw std::invalid_argument("ballbar: " + m.coordinates[static_cast<std::size_t>(i)] +
                                  " is a rotary axis: a ballbar circle needs two linear axes");
    }
  }
  if (!(c.radius_mm > 0)) throw std::invalid_argument("ballbar: the radius must be > 0");
  return {static_cast<std::size_t>(i1), static_cast<std::size_t>(i2)};
}

// The pose at the circle's centre; coordinates the centre does not name are 0.
std::vector<double> centre_pose(const BallbarMachine& m, const BallbarCircle& c) {
  std::vector<double> q(m.coordinates.size(), 0.0);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const auto it = c.centre.find(m.coordinates[i]);
    if (it != c.centre.end()) q[i] = it->second;
  }
  return q;
}

// The nominal vector from the table ball to the tool ball (workpiece frame, mm) at each angle.
std::vector<V3> nominal_vectors(const BallbarMachine& m, const BallbarCircle& c,
                                const std::vector<double>& angles_deg) {
  const auto [i1, i2] = plane_indices(m, c);
  std::vector<V3> out;
  out.reserve(angles_deg.size());
  const double r = c.radius_mm;
  if (!m.nominal) {
    V3 e1, e2;
    for (const auto& [name, e] : {std::pair{c.first, &e1}, std::pair{c.second, &e2}}) {
      if (!letter_direction(name, *e)) {
        throw std::invalid_argument(
            "ballbar: no nominal direction for coordinate '" + name +
            "' (the letter rule knows X, Y, Z, U, V, W): build the BallbarMachine from the "
            "machine description");
      }
    }
    for (double a : angles_deg) {
      const double ca = std::cos(rad(a)), sa = std::sin(rad(a));
      out.push_back({r * (ca * e1[0] + sa * e2[0]), r * (ca * e1[1] + sa * e2[1]),
                     r * (ca * e1[2] + sa * e2[2])});
    }
    return out;
  }
  // The machine's kinematics: the unit motions of the two coordinates must be orthonormal, or the
  // programmed circle is no circle between the balls.
  const std::vector<double> q = centre_pose(m, c);
  V3 pc, p;
  m.nominal(q.data(), pc.data());
  auto motion = [&](std::size_t i) {
    std::vector<double> qp = q, qm = q;
    qp[i] += c.radius_mm / m.to_base[i];
    qm[i] -= c.radius_mm / m.to_base[i];
    V3 a, b;
    m.nominal(qp.data(), a.data());
    m.nominal(qm.data(), b.data());
    return V3{(a[0] - b[0]) / (2 * r), (a[1] - b[1]) / (2 * r), (a[2] - b[2]) / (2 * r)};
  };
  const V3 e1 = motion(i1), e2 = motion(i2);
  const double tol = 1e-9 * (1.0 + r + norm(pc));
  if (std::abs(norm(e1) - 1) > 1e-9 || std::abs(norm(e2) - 1) > 1e-9 ||
      std::abs(dot(e1, e2)) > 1e-9) {
    throw std::invalid_argument(
        "ballbar: the nominal motions of " + c.first + " and " + c.second +
        " are not orthogonal unit vectors in the workpiece frame (|e_" + c.first +
        "| = " + format_short(norm(e1)) + ", |e_" + c.second + "| = " + format_short(norm(e2)) +
        ", cos = " + format_short(dot(e1, e2)) + "): the programmed circle is not a circle");
  }
  for (double a : angles_deg) {
    const std::vector<double> qa = ballbar_pose(m, c, a);
    m.nominal(qa.data(), p.data());
    const V3 v{p[0] - pc[0], p[1] - pc[1], p[2] - pc[2]};
    const double ca = std::cos(rad(a)), sa = std::sin(rad(a));
    const V3 expect{r * (ca * e1[0] + sa * e2[0]), r * (ca * e1[1] + sa * e2[1]),
                    r * (ca * e1[2] + sa * e2[2])};
    const V3 diff{v[0] - expect[0], v[1] - expect[1], v[2] - expect[2]};
    if (norm(diff) > tol) {
      throw std::invalid_argument(
          "ballbar: the nominal path of the tool relative to the workpiece is not a circle at "
          "θ = " +
          format_short(a) + "° (off by " + format_short(norm(diff)) + " mm)");
    }
    out.push_back(v);
  }
  return out;
}

// ---- Least squares and statistics ------------------------------------------------------------

// Distinct angles in [0, 360), sorted, and the largest gap between neighbours (periodic).
struct AngleCover {
  std::vector<double> distinct;
  double max_gap_deg = 360;
  double gap_from_deg = 0;
};

AngleCover angle_cover(const std::vector<double>& angles_deg) {
  AngleCover c;
  std::vector<double> w;
  w.reserve(angles_deg.size());
  for (double a : angles_deg) w.push_back(wrap_deg(a));
  std::sort(w.begin(), w.end());
  for (double a : w) {
    if (c.distinct.empty() || a - c.distinct.back() > kSameAngleDeg) c.distinct.push_back(a);
  }
  if (c.distinct.size() > 1 && 360.0 - c.distinct.back() + c.distinct.front() <= kSameAngleDeg) {
    c.distinct.pop_back();  // 359.9999999999 and 0 are one point
  }
  if (c.distinct.size() < 2) return c;
  c.max_gap_deg = 360.0 - c.distinct.back() + c.distinct.front();
  c.gap_from_deg = c.distinct.back();
  for (std::size_t i = 1; i < c.distinct.size(); ++i) {
    const double gap = c.distinct[i] - c.distinct[i - 1];
    if (gap > c.max_gap_deg) {
      c.max_gap_deg = gap;
      c.gap_from_deg = c.distinct[i - 1];
    }
  }
  return c;
}

// Coefficients of dr ≈ x0 + Σ_k (x_{2k-1} cos kθ + x_{2k} sin kθ), k = 1..order; empty when the
// design matrix is rank deficient.
std::vector<double> fourier_fit(const std::vector<double>& angles_deg,
                                const std::vector<double>& values, int order) {
  const auto n = static_cast<Eigen::Index>(angles_deg.size());
  const Eigen::Index cols = 1 + 2 * order;
  Eigen::MatrixXd a(n, cols);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = rad(angles_deg[static_cast<std::size_t>(i)]);
    a(i, 0) = 1;
    for (int k = 1; k <= order; ++k) {
      a(i, 2 * k - 1) = std::cos(k * t);
      a(i, 2 * k) = std::sin(k * t);
    }
    y(i) = values[static_cast<std::size_t>(i)];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < cols) return {};
  const Eigen::VectorXd x = qr.solve(y);
  return std::vector<double>(x.data(), x.data() + x.size());
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i] / n;
    mb += b[i] / n;
  }
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  // A constant trace (relative to the other's scale) has no correlation.
  if (!(saa > 0) || !(sbb > 0)) return kNaN;
  return sab / std::sqrt(saa * sbb);
}

TraceDifference difference_of(const std::vector<double>& m, const std::vector<double>& p) {
  TraceDifference d;
  const double n = static_cast<double>(m.size());
  double ss = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    const double e = m[i] - p[i];
    d.mean_um += e / n;
    ss += e * e;
    d.max_abs_um = std::max(d.max_abs_um, std::abs(e));
  }
  d.rms_um = std::sqrt(ss / n);
  d.correlation = pearson(m, p);
  return d;
}

}  // namespace

// ---- Machines ----------------------------------------------------------------------------------

BallbarMachine ballbar_machine_by_letters(const std::vector<std::string>& coordinates) {
  BallbarMachine m;
  m.coordinates = coordinates;
  m.units.assign(coordinates.size(), "mm");
  m.to_base.assign(coordinates.size(), 1.0);
  m.prismatic.assign(coordinates.size(), true);
  m.min.assign(coordinates.size(), 0.0);
  m.max.assign(coordinates.size(), 0.0);
  return m;
}

// ---- Circles -----------------------------------------------------------------------------------

BallbarCircle parse_ballbar_circle(const MeasurementTable& table, const BallbarMachine& machine,
                                   const BallbarFlags& flags) {
  SettingSource src;
  src.keys = &table.header_keys;
  src.key_lines = &table.header_key_lines;
  src.file = table.file;
  src.header_line = table.header_line;
  return parse_circle(src, machine, flags);
}

BallbarCircle parse_ballbar_circle(const BallbarFlags& flags, const BallbarMachine& machine) {
  return parse_circle(SettingSource{}, machine, flags);
}

std::vector<double> ballbar_pose(const BallbarMachine& machine, const BallbarCircle& circle,
                                 double angle_deg) {
  const auto [i1, i2] = plane_indices(machine, circle);
  std::vector<double> q = centre_pose(machine, circle);
  const double t = rad(angle_deg);
  q[i1] += circle.radius_mm / machine.to_base[i1] * std::cos(t);
  q[i2] += circle.radius_mm / machine.to_base[i2] * std::sin(t);
  return q;
}

std::vector<std::array<double, 3>> ballbar_directions(const BallbarMachine& machine,
                                                      const BallbarCircle& circle,
                                                      const std::vector<double>& angles_deg) {
  std::vector<std::array<double, 3>> out;
  for (const V3& v : nominal_vectors(machine, circle, angles_deg)) {
    const double len = norm(v);
    out.push_back({v[0] / len, v[1] / len, v[2] / len});
  }
  return out;
}

std::vector<double> ballbar_angles(const BallbarCircle& circle, std::size_t points) {
  if (points == 0) throw std::invalid_argument("ballbar: a trace needs at least one point");
  std::vector<double> a(points);
  for (std::size_t k = 0; k < points; ++k) {
    const double step = 360.0 * static_cast<double>(k) / static_cast<double>(points);
    a[k] = wrap_deg(circle.start_angle_deg + circle.feed * step);
  }
  return a;
}

// ---- Prediction --------------------------------------------------------------------------------

BallbarTrace predict_ballbar(const BallbarMachine& machine, const BallbarCircle& circle,
                             const DeviationFn& deviation, std::size_t points,
                             RadialProjection projection) {
  return predict_ballbar_at(machine, circle, deviation, ballbar_angles(circle, points), projection);
}

BallbarTrace predict_ballbar_at(const BallbarMachine& machine, const BallbarCircle& circle,
                                const DeviationFn& deviation, const std::vector<double>& angles_deg,
                                RadialProjection projection) {
  if (circle.feed != 1 && circle.feed != -1) {
    throw std::invalid_argument("ballbar: feed must be +1 (ccw) or -1 (cw)");
  }
  const std::vector<V3> v = nominal_vectors(machine, circle, angles_deg);
  BallbarTrace trace;
  trace.feed = circle.feed;
  trace.angle_deg = angles_deg;
  trace.dr_um.reserve(angles_deg.size());
  std::array<double, 6> out{};
  for (std::size_t k = 0; k < angles_deg.size(); ++k) {
    const std::vector<double> q = ballbar_pose(machine, circle, angles_deg[k]);
    out.fill(kNaN);
    deviation(q.data(), out.data());
    const V3 d{out[0], out[1], out[2]};
    if (!std::isfinite(d[0]) || !std::isfinite(d[1]) || !std::isfinite(d[2])) {
      throw std::invalid_argument("ballbar: the deviation at θ = " + format_short(angles_deg[k]) +
                                  "° is not finite");
    }
    const double len = norm(v[k]);
    double dr_mm;
    if (projection == RadialProjection::FirstOrder) {
      dr_mm = dot(v[k], d) / len;
    } else {
      const V3 w{v[k][0] + d[0], v[k][1] + d[1], v[k][2] + d[2]};
      dr_mm = norm(w) - len;
    }
    trace.dr_um.push_back(1000.0 * dr_mm);
  }
  return trace;
}

// ---- Measured traces ---------------------------------------------------------------------------

std::vector<BallbarTrace> ballbar_traces(const MeasurementTable& table,
                                         const BallbarCircle& circle) {
  const std::vector<double>& angle = table.column("angle_deg");
  const std::vector<double>& dr = table.column("dr_um");
  const std::vector<double>* dir = table.has("dir") ? &table.column("dir") : nullptr;
  const std::vector<double>* cycle = table.has("cycle") ? &table.column("cycle") : nullptr;
  std::vector<BallbarTrace> traces;
  for (std::size_t i = 0; i < table.rows(); ++i) {
    if (std::isnan(dr[i])) continue;  // not measured
    if (std::isnan(angle[i])) {
      throw InputError(table.cell(i, "angle_deg"),
                       "ballbar: angle_deg is empty in a row with dr_um (every measured point "
                       "needs its angle)");
    }
    const int feed = dir && !std::isnan((*dir)[i]) ? static_cast<int>((*dir)[i]) : circle.feed;
    const int run = cycle && !std::isnan((*cycle)[i]) ? static_cast<int>((*cycle)[i]) : 0;
    auto it = std::find_if(traces.begin(), traces.end(),
                           [&](const BallbarTrace& t) { return t.feed == feed && t.cycle == run; });
    if (it == traces.end()) {
      traces.emplace_back();
      it = traces.end() - 1;
      it->feed = feed;
      it->cycle = run;
    }
    it->angle_deg.push_back(angle[i]);
    it->dr_um.push_back(dr[i]);
    it->lines.push_back(table.lines[i]);
  }
  if (traces.empty()) {
    throw InputError(SourceLoc{table.file, table.header_line, 0},
                     "ballbar: no measured points (every dr_um cell is empty)");
  }
  return traces;
}

// ---- Evaluation --------------------------------------------------------------------------------

BallbarEvaluation evaluate_ballbar(const std::vector<double>& angle_deg,
                                   const std::vector<double>& dr_um, double radius_mm,
                                   int max_harmonic) {
  if (angle_deg.size() != dr_um.size()) {
    throw std::invalid_argument("ballbar: " + std::to_string(angle_deg.size()) + " angles but " +
                                std::to_string(dr_um.size()) + " radial deviations");
  }
  if (!(radius_mm > 0)) throw std::invalid_argument("ballbar: the radius must be > 0");
  if (max_harmonic < 1) throw std::invalid_argument("ballbar: max_harmonic must be >= 1");
  for (std::size_t i = 0; i < angle_deg.size(); ++i) {
    if (!std::isfinite(angle_deg[i]) || !std::isfinite(dr_um[i])) {
      throw std::invalid_argument("ballbar: point " + std::to_string(i + 1) +
                                  " is not finite (angle " + format_short(angle_deg[i]) +
                                  " deg, dr " + format_short(dr_um[i]) + " um)");
    }
  }
  const AngleCover cover = angle_cover(angle_deg);
  if (cover.distinct.size() < 3) {
    throw std::invalid_argument("ballbar: " + std::to_string(cover.distinct.size()) +
                                " distinct angles: the centre fit needs at least 3");
  }
  BallbarEvaluation e;
  e.points = angle_deg.size();
  e.coverage_deg = 360.0 - cover.max_gap_deg;
  const std::vector<double> centre = fourier_fit(angle_deg, dr_um, 1);
  if (centre.empty()) throw std::invalid_argument("ballbar: the centre fit is singular");
  e.radius_deviation_um = centre[0];
  e.centre_offset_um = {centre[1], centre[2]};
  const auto [lo, hi] = std::minmax_element(dr_um.begin(), dr_um.end());
  e.max_minus_min_um = *hi - *lo;
  e.centred_um.reserve(dr_um.size());
  for (std::size_t i = 0; i < dr_um.size(); ++i) {
    const double t = rad(angle_deg[i]);
    e.centred_um.push_back(dr_um[i] - centre[1] * std::cos(t) - centre[2] * std::sin(t));
  }
  const auto [clo, chi] = std::minmax_element(e.centred_um.begin(), e.centred_um.end());
  e.circular_deviation_um = *chi - *clo;
  e.radial_deviation_max_um = *chi;
  e.radial_deviation_min_um = *clo;
  if (cover.distinct.size() >= 4) {
    const MinimumZone z = minimum_zone(angle_deg, dr_um);
    e.mz_centre_offset_um = z.centre_um;
    e.mz_circular_deviation_um = z.width_um;
    e.mz_radius_deviation_um = z.mid_um;
  } else {
    e.mz_centre_offset_um = e.centre_offset_um;
    e.mz_circular_deviation_um = e.circular_deviation_um;
    e.mz_radius_deviation_um = 0.5 * (*chi + *clo);
  }
  // Harmonics need the circle sampled finer than half the period of the highest order.
  e.squareness_urad = e.scale_mismatch_um_per_m = kNaN;
  const auto needed = static_cast<std::size_t>(2 * max_harmonic + 1);
  if (cover.distinct.size() >= needed && cover.max_gap_deg < 180.0 / max_harmonic) {
    const std::vector<double> x = fourier_fit(angle_deg, dr_um, max_harmonic);
    for (int k = 2; k <= max_harmonic && !x.empty(); ++k) {
      BallbarHarmonic h;
      h.order = k;
      h.cos_um = x[static_cast<std::size_t>(2 * k - 1)];
      h.sin_um = x[static_cast<std::size_t>(2 * k)];
      h.amplitude_um = std::hypot(h.cos_um, h.sin_um);
      h.phase_deg =
          h.amplitude_um > 0 ? wrap_deg(std::atan2(h.sin_um, h.cos_um) * 180.0 / kPi) / k : 0.0;
      e.harmonics.push_back(h);
    }
    if (!e.harmonics.empty()) {
      // sin 2θ = S·R/2 and cos 2θ = (k1 − k2)·R/2 (µm, R in mm): per mm -> µrad and µm/m.
      e.squareness_urad = 2000.0 * e.harmonics[0].sin_um / radius_mm;
      e.scale_mismatch_um_per_m = 2000.0 * e.harmonics[0].cos_um / radius_mm;
    }
  }
  return e;
}

MinimumZone minimum_zone(const std::vector<double>& angle_deg, const std::vector<double>& dr_um) {
  if (angle_deg.size() != dr_um.size())
    throw std::invalid_argument("ballbar: angles and radial deviations differ in size");
  if (angle_cover(angle_deg).distinct.size() < 4)
    throw std::invalid_argument("ballbar: the minimum zone needs at least 4 distinct angles");
  // The dual of  min h  s.t. |dr_i − m − a cos θ_i − b sin θ_i| <= h:
  //   max Σ dr_i (p_i − q_i)  s.t.  Σ (p − q) = Σ (p − q) cos θ = Σ (p − q) sin θ = 0,
  //   Σ (p + q) = 1, p, q >= 0;  its four rows' prices are (m, a, b, h). Revised simplex with
  //   four artificial columns (big M) and Bland's rule, which cannot cycle.
  const std::size_t n = dr_um.size(), cols = 2 * n + 4;
  double scale = 1;
  for (double v : dr_um) scale = std::max(scale, std::abs(v));
  const double big = 1e3 * scale, tol = 1e-11 * scale;
  std::vector<double> cosines(n), sines(n);
  for (std::size_t i = 0; i < n; ++i)
    cosines[i] = std::cos(rad(angle_deg[i])), sines[i] = std::sin(rad(angle_deg[i]));
  auto column = [&](std::size_t j) {
    Eigen::Vector4d a = Eigen::Vector4d::Zero();
    if (j >= 2 * n) {
      a(static_cast<Eigen::Index>(j - 2 * n)) = 1;
      return a;
    }
    const double sign = j < n ? 1.0 : -1.0;
    a << sign, sign * cosines[j % n], sign * sines[j % n], 1;
    return a;
  };
  auto cost = [&](std::size_t j) { return j >= 2 * n ? -big : (j < n ? dr_um[j] : -dr_um[j - n]); };
  std::array<std::size_t, 4> basis = {2 * n, 2 * n + 1, 2 * n + 2, 2 * n + 3};
  Eigen::Vector4d x(0, 0, 0, 1);
  Eigen::Matrix4d inverse = Eigen::Matrix4d::Identity();
  Eigen::RowVector4d price;
  for (std::size_t iteration = 0; iteration < 100 * cols; ++iteration) {
    Eigen::RowVector4d cb;
    for (int i = 0; i < 4; ++i) cb(i) = cost(basis[static_cast<std::size_t>(i)]);
    price = cb * inverse;
    std::size_t enter = cols;
    for (std::size_t j = 0; j < cols && enter == cols; ++j) {
      if (std::find(basis.begin(), basis.end(), j) != basis.end()) continue;
      if (cost(j) - price.dot(column(j)) > tol) enter = j;
    }
    if (enter == cols) break;  // optimal
    const Eigen::Vector4d w = inverse * column(enter);
    int leave = -1;
    double best = INFINITY;
    for (int i = 0; i < 4; ++i) {
      if (w(i) <= 1e-12) continue;
      const double ratio = x(i) / w(i);
      if (ratio < best - 1e-15 ||
          (ratio <= best + 1e-15 && leave >= 0 &&
           basis[static_cast<std::size_t>(i)] < basis[static_cast<std::size_t>(leave)]))
        best = ratio, leave = i;
    }
    if (leave < 0) throw std::runtime_error("ballbar: the minimum-zone programme is unbounded");
    basis[static_cast<std::size_t>(leave)] = enter;
    Eigen::Matrix4d B;
    for (int i = 0; i < 4; ++i) B.col(i) = column(basis[static_cast<std::size_t>(i)]);
    inverse = B.inverse();
    x = inverse * Eigen::Vector4d(0, 0, 0, 1);
  }
  // The zone from the prices' centre, evaluated on the data (exact whatever the last rounding).
  MinimumZone z;
  z.centre_um = {price(1), price(2)};
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = rad(angle_deg[i]);
    const double r = dr_um[i] - z.centre_um[0] * std::cos(t) - z.centre_um[1] * std::sin(t);
    lo = std::min(lo, r), hi = std::max(hi, r);
  }
  z.width_um = hi - lo;
  z.mid_um = 0.5 * (hi + lo);
  return z;
}

std::vector<int> ballbar_travel_direction(const std::vector<double>& angle_deg, int feed,
                                          int axis) {
  if (feed != 1 && feed != -1) throw std::invalid_argument("ballbar: feed must be +1 or -1");
  // The motion just before the point: first = c1 + R cos θ moves as −feed sin θ, second as
  // feed cos θ.
  std::vector<int> out;
  out.reserve(angle_deg.size());
  for (double a : angle_deg) {
    const double t = rad(a) - feed * 1e-7;
    const double v = axis == 0 ? -feed * std::sin(t) : feed * std::cos(t);
    out.push_back(v >= 0 ? 1 : -1);
  }
  return out;
}

BallbarEvaluation evaluate_ballbar(const BallbarTrace& trace, double radius_mm, int max_harmonic) {
  return evaluate_ballbar(trace.angle_deg, trace.dr_um, radius_mm, max_harmonic);
}

std::vector<double> interpolate_trace(const BallbarTrace& trace,
                                      const std::vector<double>& angles_deg, double max_gap_deg) {
  if (trace.angle_deg.size() != trace.dr_um.size()) {
    throw std::invalid_argument("ballbar: trace angles and values differ in size");
  }
  // Sorted (angle, value), points at one angle averaged.
  std::vector<std::pair<double, double>> pts;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    if (!std::isfinite(trace.angle_deg[i]) || !std::isfinite(trace.dr_um[i])) {
      throw std::invalid_argument("ballbar: trace point " + std::to_string(i + 1) +
                                  " is not finite");
    }
    pts.emplace_back(wrap_deg(trace.angle_deg[i]), trace.dr_um[i]);
  }
  std::sort(pts.begin(), pts.end());
  std::vector<double> a, v;
  std::vector<int> count;
  for (const auto& [angle, value] : pts) {
    if (!a.empty() && angle - a.back() <= kSameAngleDeg) {
      v.back() += value;
      ++count.back();
    } else {
      a.push_back(angle);
      v.push_back(value);
      count.push_back(1);
    }
  }
  for (std::size_t i = 0; i < v.size(); ++i) v[i] /= count[i];
  if (a.size() > 1 && 360.0 - a.back() + a.front() <= kSameAngleDeg) {
    v.front() =
        (v.front() * count.front() + v.back() * count.back()) / (count.front() + count.back());
    a.pop_back();
    v.pop_back();
  }
  const AngleCover cover = angle_cover(a);
  if (a.size() < 2) {
    throw std::invalid_argument(
        "ballbar: a trace with fewer than 2 distinct angles cannot be "
        "interpolated");
  }
  if (cover.max_gap_deg > max_gap_deg) {
    throw std::invalid_argument("ballbar: the trace has a gap of " +
                                format_short(cover.max_gap_deg) + " deg after " +
                                format_short(cover.gap_from_deg) + " deg (more than " +
                                format_short(max_gap_deg) + " deg): it does not cover the circle");
  }
  std::vector<double> out;
  out.reserve(angles_deg.size());
  const std::size_t n = a.size();
  for (double raw : angles_deg) {
    if (!std::isfinite(raw)) throw std::invalid_argument("ballbar: an angle is not finite");
    const double t = wrap_deg(raw);
    const std::size_t hi =
        static_cast<std::size_t>(std::upper_bound(a.begin(), a.end(), t) - a.begin());
    // Neighbours lo < t <= hi, periodic: before a[0] and after a[n-1] the wrap segment.
    const std::size_t i0 = hi == 0 ? n - 1 : hi - 1;
    const std::size_t i1 = hi == n ? 0 : hi;
    double a0 = a[i0], a1 = a[i1];
    double tt = t;
    if (a1 <= a0) {  // the wrap segment
      a1 += 360.0;
      if (tt < a0) tt += 360.0;
    }
    const double w = (tt - a0) / (a1 - a0);
    out.push_back(v[i0] + w * (v[i1] - v[i0]));
  }
  return out;
}

double circular_hysteresis_um(const BallbarTrace& a, const BallbarTrace& b, double max_gap_deg) {
  const std::vector<double> bi = interpolate_trace(b, a.angle_deg, max_gap_deg);
  double h = 0;
  for (std::size_t i = 0; i < bi.size(); ++i) h = std::max(h, std::abs(a.dr_um[i] - bi[i]));
  return h;
}

BallbarComparison compare_ballbar(const BallbarTrace& measured, const BallbarTrace& predicted,
                                  double radius_mm, double max_gap_deg, int max_harmonic) {
  if (measured.angle_deg.size() != measured.dr_um.size() || measured.size() == 0) {
    throw std::invalid_argument("ballbar: the measured trace is empty or inconsistent");
  }
  BallbarComparison c;
  c.feed = measured.feed;
  c.cycle = measured.cycle;
  c.angle_deg = measured.angle_deg;
  c.measured_um = measured.dr_um;
  c.predicted_um =
      predicted.angle_deg == measured.angle_deg && predicted.dr_um.size() == measured.size()
          ? predicted.dr_um
          : interpolate_trace(predicted, measured.angle_deg, max_gap_deg);
  c.raw = difference_of(c.measured_um, c.predicted_um);
  c.measured = evaluate_ballbar(c.angle_deg, c.measured_um, radius_mm, max_harmonic);
  c.predicted = evaluate_ballbar(c.angle_deg, c.predicted_um, radius_mm, max_harmonic);
  c.centred = difference_of(c.measured.centred_um, c.predicted.centred_um);
  std::vector<double> diff(c.measured_um.size());
  for (std::size_t i = 0; i < diff.size(); ++i) diff[i] = c.measured_um[i] - c.predicted_um[i];
  c.difference = evaluate_ballbar(c.angle_deg, diff, radius_mm, max_harmonic);
  return c;
}

}  // namespace weilgen
