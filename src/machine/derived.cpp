#include "weilgen/machine/derived.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <stdexcept>

#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {
namespace {

std::vector<std::string> point_names(const Description& d) {
  std::vector<std::string> out;
  for (const ChainPoint& p : d.points) out.push_back(p.name);
  return out;
}

// Index of the entry called `name` in chain points or directions, -1 when none.
template <typename T>
int index_of(const std::vector<T>& entries, const std::string& name) {
  for (std::size_t i = 0; i < entries.size(); ++i)
    if (entries[i].name == name) return static_cast<int>(i);
  return -1;
}

std::vector<std::string> point_and_direction_names(const Description& d) {
  std::vector<std::string> out = point_names(d);
  for (const ChainDirection& u : d.directions) out.push_back(u.name);
  return out;
}

std::vector<std::string> coordinate_names(const Description& d) {
  std::vector<std::string> out;
  for (const Body& b : d.bodies)
    if (b.joint.type != JointType::Fixed) out.push_back(b.joint.coordinate);
  return out;
}

std::string listed(const std::vector<std::string>& names) {
  return names.empty() ? "none" : join(names);
}

// The derived quantity's, link's or output's checks, with its location and name for messages.
class Checker {
 public:
  explicit Checker(Description& d) : d_(d) {}

  void run() {
    check_links();
    for (std::size_t i = 0; i < d_.derived.size(); ++i) {
      Derived& q = d_.derived[i];
      const std::string what = "derived." + q.name;
      bool nominal = true;
      for (const std::string& n : q.value.params())
        nominal &= ref_is_nominal(resolve(n, i, q.loc, what));
      check_operations(q.value, i, q.loc, what);
      q.nominal = nominal;
    }
    if (!d_.output) return;
    const std::size_t all = d_.derived.size();
    for (std::size_t k = 0; k < d_.output->steps.size(); ++k) {
      const TransformStep& s = d_.output->steps[k];
      const std::string what = "output.transform[" + std::to_string(k) + "]";
      if (s.kind == TransformStep::Kind::Translate) {
        for (const Expr& e : s.translation) check_expression(e, all, s.loc, what);
        continue;
      }
      check_expression(s.amount, all, s.loc, what);
      for (const Expr& e : s.v) {
        check_expression(e, all, s.loc, what);
        refuse_direction(e, all, s.loc, what, "the twist's v =");
        if (!is_nominal(e, all, s.loc, what)) {
          throw InputError(s.loc, what + ": the twist's v = '" + e.str() +
                                      "' depends on errors; a twist's axis must be nominal (put "
                                      "the error dependence in 'by')");
        }
      }
    }
    for (const Expr& e : d_.output->point) {
      check_expression(e, all, d_.output->loc, "output.point");
      if (!is_nominal(e, all, d_.output->loc, "output.point")) {
        throw InputError(d_.output->loc, "output.point: '" + e.str() + "' depends on errors (" +
                                             error_source(e, all) +
                                             "); the point is nominal: put error terms into a "
                                             "translate step");
      }
    }
  }

 private:
  NameRef resolve(const std::string& n, std::size_t before, const SourceLoc& loc,
                  const std::string& what) const {
    try {
      return resolve_name(d_, n, before);
    } catch (const std::invalid_argument& e) {
      throw InputError(loc, what + ": " + e.what());
    }
  }

  bool ref_is_nominal(const NameRef& r) const {
    if (r.kind == NameRef::Kind::PointComponent) return false;
    if (r.kind == NameRef::Kind::Derived) return d_.derived[static_cast<size_t>(r.index)].nominal;
    return true;
  }

  bool is_nominal(const Expr& e, std::size_t before, const SourceLoc& loc,
                  const std::string& what) const {
    for (const std::string& n : e.params())
      if (!ref_is_nominal(resolve(n, before, loc, what))) return false;
    return true;
  }

  // The first direction component `e` uses, directly or through derived quantities, else "".
  // Directions are nominal but only the chains evaluate them: the loader cannot, so they may
  // not be divisors (whose travel-range check evaluates them) nor twist axes.
  std::string direction_used(const Expr& e, std::size_t before) const {
    for (const std::string& n : e.params()) {
      const NameRef r = resolve_name(d_, n, before);
      if (r.kind == NameRef::Kind::DirectionComponent) return n;
      if (r.kind != NameRef::Kind::Derived) continue;
      const auto i = static_cast<std::size_t>(r.index);
      if (std::string via = direction_used(d_.derived[i].value, i); !via.empty()) return via;
    }
    return "";
  }

  void refuse_direction(const Expr& e, std::size_t before, const SourceLoc& loc,
                        const std::string& what, const std::string& role) const {
    const std::string via = direction_used(e, before);
    if (via.empty()) return;
    throw InputError(loc, what + ": " + role + " '" + e.str() + "' uses the direction component '" +
                              via + "'; directions may multiply deviations but cannot be " +
                              "divisors or twist axes");
  }

  // The first name that makes `e` depend on errors (a point, or a derived quantity that does).
  std::string error_source(const Expr& e, std::size_t before) const {
    for (const std::string& n : e.params()) {
      const NameRef r = resolve_name(d_, n, before);
      if (!ref_is_nominal(r)) return n;
    }
    return "";
  }

  void check_expression(const Expr& e, std::size_t before, const SourceLoc& loc,
                        const std::string& what) {
    for (const std::string& n : e.params()) resolve(n, before, loc, what);
    check_operations(e, before, loc, what);
  }

  // Divisors must be nominal and non-zero over the travel range; powers of error-dependent
  // quantities must have whole, non-negative exponents (the algebra has no inverse of an error).
  void check_operations(const Expr& e, std::size_t before, const SourceLoc& loc,
                        const std::string& what) {
    if (e.a) check_operations(*e.a, before, loc, what);
    if (e.b) check_operations(*e.b, before, loc, what);
    if (e.kind == Expr::Kind::Div) {
      refuse_direction(*e.b, before, loc, what, "the divisor");
      if (!is_nominal(*e.b, before, loc, what)) {
        throw InputError(loc, what + ": divides by '" + e.b->str() +
                                  "', which depends on errors (" + error_source(*e.b, before) +
                                  "); only nominal divisors (parameters, coordinates and "
                                  "quantities without errors) are allowed");
      }
      check_nonzero(*e.b, before, loc, what);
    } else if (e.kind == Expr::Kind::Pow) {
      if (!e.b->is_number())
        throw InputError(loc, what + ": the exponent '" + e.b->str() + "' must be a number");
      const double k = e.b->number;
      const bool nominal = is_nominal(*e.a, before, loc, what);
      if (!nominal && (k < 0 || k != std::floor(k))) {
        throw InputError(loc, what + ": '" + e.a->str() + "' depends on errors, so its exponent " +
                                  "must be a whole number >= 0, not " + format_short(k));
      }
      if (nominal && k < 0) {
        refuse_direction(*e.a, before, loc, what, "the divisor");
        check_nonzero(*e.a, before, loc, what);
      }
    }
  }

  // Independent coordinates (bodies) that `e` depends on, through links and nominal derived.
  void coordinates_of(const Expr& e, std::size_t before, std::set<int>& out) const {
    for (const std::string& n : e.params()) {
      const NameRef r = resolve_name(d_, n, before);
      if (r.kind == NameRef::Kind::Coordinate) {
        const Joint& j = d_.bodies[static_cast<size_t>(r.index)].joint;
        if (j.link)
          coordinates_of(*j.link, before, out);
        else
          out.insert(r.index);
      } else if (r.kind == NameRef::Kind::Derived) {
        coordinates_of(d_.derived[static_cast<size_t>(r.index)].value, static_cast<size_t>(r.index),
                       out);
      }
    }
  }

  // Evaluates the nominal divisor on a grid over the travel range of the coordinates it uses
  // (parameters at their defaults). A sign change between grid points or a value that vanishes
  // relative to the others means the divisor is zero somewhere in the range.
  void check_nonzero(const Expr& den, std::size_t before, const SourceLoc& loc,
                     const std::string& what) {
    std::set<int> used;
    coordinates_of(den, before, used);
    const std::vector<int> axes(used.begin(), used.end());
    const std::size_t k = axes.size();
    const int per_axis = k <= 1 ? 257 : k == 2 ? 33 : k == 3 ? 9 : 3;
    std::vector<int> idx(k, 0);
    double vmax = 0;
    struct Sample {
      double value;
      std::map<std::string, double> at;
    };
    std::vector<Sample> samples;
    for (;;) {
      std::map<std::string, double> values = d_.parameter_defaults();
      for (const Body& b : d_.bodies)
        if (b.joint.type != JointType::Fixed && !b.joint.link)
          values[b.joint.coordinate] = b.joint.min;
      std::map<std::string, double> at;
      for (std::size_t a = 0; a < k; ++a) {
        const Joint& j = d_.bodies[static_cast<size_t>(axes[a])].joint;
        const double t = per_axis == 1 ? 0.0 : static_cast<double>(idx[a]) / (per_axis - 1);
        values[j.coordinate] = j.min + t * (j.max - j.min);
        at[j.coordinate] = values[j.coordinate];
      }
      resolve_links(d_, values);
      for (std::size_t i = 0; i < before; ++i)
        if (d_.derived[i].nominal && direction_used(d_.derived[i].value, i).empty())
          values[d_.derived[i].name] = d_.derived[i].value.eval(values);
      const double v = den.eval(values);
      if (!std::isfinite(v)) {
        throw InputError(loc,
                         what + ": the divisor '" + den.str() + "' is not finite at " + where(at));
      }
      vmax = std::max(vmax, std::abs(v));
      samples.push_back({v, at});
      std::size_t a = 0;
      while (a < k && ++idx[a] == per_axis) idx[a++] = 0;
      if (a == k) break;
    }
    const Sample* pos = nullptr;
    const Sample* neg = nullptr;
    for (const Sample& s : samples) {
      if (std::abs(s.value) <= 1e-12 * std::max(1.0, vmax)) {
        throw InputError(loc, what + ": the divisor '" + den.str() + "' is zero at " + where(s.at) +
                                  range_note(axes));
      }
      (s.value > 0 ? pos : neg) = &s;
    }
    if (pos && neg) {
      throw InputError(loc, what + ": the divisor '" + den.str() + "' is zero within the travel " +
                                "range: it is " + format_short(pos->value) + " at " +
                                where(pos->at) + " and " + format_short(neg->value) + " at " +
                                where(neg->at) + range_note(axes));
    }
  }

  std::string where(const std::map<std::string, double>& at) const {
    if (at.empty()) return "every pose";
    std::string s;
    for (const auto& [name, v] : at) {
      const Joint& j = d_.bodies[static_cast<size_t>(d_.coordinate_body(name))].joint;
      s += (s.empty() ? "" : ", ") + name + " = " + format_short(v) + " " + j.unit;
    }
    return s;
  }

  std::string range_note(const std::vector<int>& axes) const {
    std::string s;
    for (int b : axes) {
      const Joint& j = d_.bodies[static_cast<size_t>(b)].joint;
      s += (s.empty() ? "" : ", ") + j.coordinate + " in [" + format_short(j.min) + ", " +
           format_short(j.max) + "] " + j.unit;
    }
    return " (" + (s.empty() ? std::string("no coordinates") : s) +
           ", parameters at their defaults)";
  }

  void check_links() {
    for (int b : d_.linked_axes()) {
      const Joint& j = d_.bodies[static_cast<size_t>(b)].joint;
      const std::string what = "bodies." + d_.bodies[static_cast<size_t>(b)].name + ".joint.linked";
      for (const std::string& n : j.link->params()) {
        const int body = d_.coordinate_body(n);
        const bool param = std::any_of(d_.parameters.begin(), d_.parameters.end(),
                                       [&](const Parameter& p) { return p.name == n; });
        if (body < 0 && !param) {
          throw InputError(j.loc, what + ": unknown name '" + n + "' in '" + j.link->str() +
                                      "' (coordinates: " + listed(coordinate_names(d_)) +
                                      "; parameters may be used too)");
        }
      }
    }
    // A link cycle: follow links depth first, reporting the first closed path.
    std::map<int, int> state;  // 0 unvisited, 1 on the path, 2 done
    std::vector<int> path;
    std::function<void(int)> visit = [&](int b) {
      state[b] = 1;
      path.push_back(b);
      for (const std::string& n : d_.bodies[static_cast<size_t>(b)].joint.link->params()) {
        const int c = d_.coordinate_body(n);
        if (c < 0 || !d_.bodies[static_cast<size_t>(c)].joint.link) continue;
        if (state[c] == 1) {
          std::string names;
          auto it = std::find(path.begin(), path.end(), c);
          for (; it != path.end(); ++it)
            names += d_.bodies[static_cast<size_t>(*it)].joint.coordinate + " -> ";
          names += d_.bodies[static_cast<size_t>(c)].joint.coordinate;
          const Joint& j = d_.bodies[static_cast<size_t>(c)].joint;
          throw InputError(j.loc, "linked coordinates form a cycle: " + names +
                                      " (a linked coordinate must come down to independent ones)");
        }
        if (state[c] == 0) visit(c);
      }
      path.pop_back();
      state[b] = 2;
    };
    for (int b : d_.linked_axes())
      if (state[b] == 0) visit(b);
  }

  Description& d_;
};

}  // namespace

NameRef resolve_name(const Description& d, const std::string& name, std::size_t derived_before) {
  NameRef r;
  if (const auto dot = name.find('.'); dot != std::string::npos) {
    const std::string base = name.substr(0, dot);
    r.component = name[dot + 1] - 'x';
    if ((r.index = index_of(d.points, base)) >= 0) {
      r.kind = NameRef::Kind::PointComponent;
      return r;
    }
    if ((r.index = index_of(d.directions, base)) >= 0) {
      r.kind = NameRef::Kind::DirectionComponent;
      return r;
    }
    if (d.directions.empty()) {
      throw std::invalid_argument("unknown chain point '" + base + "' in '" + name +
                                  "' (points: " + listed(point_names(d)) + ")");
    }
    throw std::invalid_argument(
        "unknown chain point or direction '" + base + "' in '" + name +
        "' (points and directions: " + listed(point_and_direction_names(d)) + ")");
  }
  for (std::size_t i = 0; i < d.derived.size(); ++i) {
    if (d.derived[i].name != name) continue;
    if (i >= derived_before) {
      throw std::invalid_argument("'" + name +
                                  "' is used before it is defined (derived quantities are "
                                  "evaluated in file order)");
    }
    r.kind = NameRef::Kind::Derived;
    r.index = static_cast<int>(i);
    return r;
  }
  if (const int b = d.coordinate_body(name); b >= 0) {
    r.kind = NameRef::Kind::Coordinate;
    r.index = b;
    return r;
  }
  for (std::size_t i = 0; i < d.parameters.size(); ++i) {
    if (d.parameters[i].name == name) {
      r.kind = NameRef::Kind::Parameter;
      r.index = static_cast<int>(i);
      return r;
    }
  }
  if (std::any_of(d.points.begin(), d.points.end(),
                  [&](const ChainPoint& p) { return p.name == name; })) {
    throw std::invalid_argument("'" + name + "' is a chain point: use its components '" + name +
                                ".x', '" + name + ".y', '" + name + ".z'");
  }
  if (std::any_of(d.directions.begin(), d.directions.end(),
                  [&](const ChainDirection& u) { return u.name == name; })) {
    throw std::invalid_argument("'" + name + "' is a chain direction: use its components '" + name +
                                ".x', '" + name + ".y', '" + name + ".z'");
  }
  std::vector<std::string> derived;
  for (std::size_t i = 0; i < std::min(derived_before, d.derived.size()); ++i)
    derived.push_back(d.derived[i].name);
  std::vector<std::string> params;
  for (const Parameter& p : d.parameters) params.push_back(p.name);
  throw std::invalid_argument("unknown name '" + name + "' (points: " + listed(point_names(d)) +
                              "; derived: " + listed(derived) +
                              "; coordinates: " + listed(coordinate_names(d)) +
                              "; parameters: " + listed(params) + ")");
}

std::vector<int> link_order(const Description& d) {
  std::vector<int> order;
  std::set<int> placed;
  std::function<void(int)> place = [&](int b) {
    if (placed.count(b)) return;
    placed.insert(b);  // before recursing: a (rejected) cycle cannot loop
    for (const std::string& n : d.bodies[static_cast<size_t>(b)].joint.link->params()) {
      const int c = d.coordinate_body(n);
      if (c >= 0 && d.bodies[static_cast<size_t>(c)].joint.link) place(c);
    }
    order.push_back(b);
  };
  for (int b : d.linked_axes()) place(b);
  return order;
}

void resolve_links(const Description& d, std::map<std::string, double>& values) {
  for (int b : link_order(d)) {
    const Joint& j = d.bodies[static_cast<size_t>(b)].joint;
    values[j.coordinate] = j.link->eval(values);
  }
}

void check_derived(Description& desc) { Checker(desc).run(); }

}  // namespace weilgen
