#include "weilgen/analysis/study_spec.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {
namespace {

// "--grid: \"X=0:1000:0\"" : the prefix of every message about one flag value.
std::string flag_context(const std::string& flag, const std::string& text) {
  return flag + ": " + quoted(abbreviated(text));
}

[[noreturn]] void fail(const std::string& context, const std::string& why) {
  throw std::invalid_argument(context + ": " + why);
}

// ---- Poses -----------------------------------------------------------------------------------

struct Axis {
  std::string name;
  std::string unit;
  UnitFactor factor;
  bool angle = false;
  double min = 0, max = 0;
  bool has_range() const { return min < max; }
  std::string range_text() const {
    return "[" + format_number(min) + ", " + format_number(max) + "] " + unit;
  }
};

std::vector<Axis> machine_axes(const Description& desc) {
  std::vector<Axis> axes;
  for (int b : desc.axes()) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(b)].joint;
    Axis a;
    a.name = j.coordinate;
    a.unit = j.unit;
    a.factor = parse_unit(j.unit);
    a.angle = j.type == JointType::Revolute;
    a.min = j.min;
    a.max = j.max;
    axes.push_back(a);
  }
  return axes;
}

std::string axes_list(const Description& desc, const std::vector<Axis>& axes) {
  std::vector<std::string> names;
  for (const Axis& a : axes) names.push_back(a.name);
  return "machine " + desc.name + " has axes " + (names.empty() ? "none" : join(names));
}

// A value of `axis` in its unit; `text` may carry a unit of the same kind.
double axis_value(const Axis& axis, const std::string& text, const std::string& context) {
  const Quantity q = parse_quantity_unit(text, axis.unit, context);
  if (q.unit.angle != axis.angle) {
    fail(context, "axis " + axis.name + " is " + (axis.angle ? "an angle" : "a length") + " in " +
                      axis.unit + ", but \"" + q.unit_name + "\" is " +
                      (q.unit.angle ? "an angle" : "a length") + " unit");
  }
  const double v = q.in(axis.factor);
  if (axis.has_range()) {
    const double slack = 1e-9 * std::max({1.0, std::abs(axis.min), std::abs(axis.max)});
    if (v < axis.min - slack || v > axis.max + slack) {
      fail(context, axis.name + " = " + format_number(v) + " " + axis.unit +
                        " is outside the axis range " + axis.range_text());
    }
  }
  return v;
}

// "AXIS=VALUE" items of one flag: (axis index, value text), each axis at most once.
std::vector<std::pair<std::size_t, std::string>> axis_items(const Description& desc,
                                                            const std::vector<Axis>& axes,
                                                            const std::string& text,
                                                            const std::string& context,
                                                            const std::string& form) {
  std::vector<std::pair<std::size_t, std::string>> out;
  if (trim(text).empty()) fail(context, "empty (expected " + form + ")");
  for (const std::string& raw : split(text, ',')) {
    const std::string item = trim(raw);
    if (item.empty()) fail(context, "empty item (expected " + form + ")");
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) {
      fail(context, quoted(abbreviated(item)) + " is not AXIS=value (expected " + form + ")");
    }
    const std::string name = trim(item.substr(0, eq));
    std::size_t index = axes.size();
    for (std::size_t i = 0; i < axes.size(); ++i) {
      if (axes[i].name == name) index = i;
    }
    if (index == axes.size()) {
      fail(context,
           "unknown axis " + quoted(abbreviated(name)) + " (" + axes_list(desc, axes) + ")");
    }
    for (const auto& [seen, value] : out) {
      if (seen == index) fail(context, "axis " + name + " is given twice");
    }
    out.emplace_back(index, trim(item.substr(eq + 1)));
  }
  return out;
}

// The value of an axis the flag does not name: 0 when 0 is within its range.
double default_axis_value(const Axis& axis, const std::string& context) {
  if (!axis.has_range() || (axis.min <= 0 && 0 <= axis.max)) return 0;
  fail(context, "axis " + axis.name + " is not given and 0 is outside its range " +
                    axis.range_text() + ": give a value (e.g. " + axis.name + "=" +
                    format_number(0.5 * (axis.min + axis.max)) + ")");
}

std::size_t grid_count(const std::string& text, const std::string& context) {
  const std::string t = trim(text);
  std::size_t n = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), n);
  if (t.empty() || ec != std::errc() || end != t.data() + t.size()) {
    if (!t.empty() && t[0] == '-') fail(context, "count must be >= 1, got " + t);
    fail(context, "count must be a whole number >= 1, got " + quoted(abbreviated(t)));
  }
  if (n < 1) fail(context, "count must be >= 1");
  return n;
}

// start:stop:count evenly spaced (start and stop exact), or one value.
std::vector<double> grid_axis_values(const Axis& axis, const std::string& text,
                                     const std::string& context) {
  const std::vector<std::string> parts = split(text, ':');
  if (parts.size() == 1) return {axis_value(axis, text, context)};
  if (parts.size() != 3) {
    fail(context, axis.name + "=" + text + " is neither a value nor start:stop:count");
  }
  const double start = axis_value(axis, parts[0], context);
  const double stop = axis_value(axis, parts[1], context);
  const std::size_t count = grid_count(parts[2], context);
  if (count > kMaxGridPoses) {
    fail(context,
         "count " + std::to_string(count) + " is more than " + std::to_string(kMaxGridPoses));
  }
  std::vector<double> values(count, start);
  for (std::size_t i = 1; i < count; ++i) {
    values[i] = i + 1 == count ? stop
                               : start + (stop - start) * static_cast<double>(i) /
                                             static_cast<double>(count - 1);
  }
  return values;
}

const char* const kAtForm = "AXIS=value,..., e.g. X=0,Y=1500,Z=600";
const char* const kGridForm = "AXIS=start:stop:count or AXIS=value,..., e.g. X=0:1000:5,Y=0";

}  // namespace

std::size_t PoseSet::grid_size() const {
  if (grid_values.empty()) return 0;
  std::size_t n = 1;
  for (const auto& v : grid_values) n *= v.size();
  return n;
}

PoseSet parse_poses(const Description& desc, const std::vector<std::string>& at,
                    const std::vector<std::string>& grid) {
  const std::vector<Axis> axes = machine_axes(desc);
  PoseSet set;
  for (const Axis& a : axes) {
    set.axes.push_back(a.name);
    set.units.push_back(a.unit);
  }
  if (at.empty() && grid.empty()) {
    std::vector<std::string> ranges;
    for (const Axis& a : axes) ranges.push_back(a.name + " " + a.range_text());
    throw std::invalid_argument("no poses: give --grid and/or --at (machine " + desc.name +
                                " axes: " + join(ranges) + ")");
  }
  if (grid.size() > 1) {
    throw std::invalid_argument("--grid: given " + std::to_string(grid.size()) +
                                " times; give one grid with all its axes (e.g. " +
                                "X=0:1000:5,Z=600:1400:5)");
  }
  if (!grid.empty()) {
    const std::string context = flag_context("--grid", grid[0]);
    const auto items = axis_items(desc, axes, grid[0], context, kGridForm);
    std::vector<double> fixed(axes.size(), 0.0);
    std::vector<bool> named(axes.size(), false);
    std::vector<std::vector<double>> values;  // of each written axis
    std::size_t total = 1;
    for (const auto& [index, text] : items) {
      named[index] = true;
      values.push_back(grid_axis_values(axes[index], text, context));
      fixed[index] = values.back().front();
      total *= values.back().size();
      if (total > kMaxGridPoses) {
        fail(context, "the grid has more than " + std::to_string(kMaxGridPoses) + " poses");
      }
      if (values.back().size() > 1) {
        set.grid_axes.push_back(index);
        set.grid_values.push_back(values.back());
      }
    }
    for (std::size_t i = 0; i < axes.size(); ++i) {
      if (!named[i]) fixed[i] = default_axis_value(axes[i], context);
    }
    // Odometer over the written axes, the last one fastest.
    std::vector<std::size_t> digit(items.size(), 0);
    set.poses.reserve(total);
    for (std::size_t k = 0; k < total; ++k) {
      std::vector<double> pose = fixed;
      for (std::size_t w = 0; w < items.size(); ++w) pose[items[w].first] = values[w][digit[w]];
      set.poses.push_back(std::move(pose));
      for (std::size_t w = items.size(); w-- > 0;) {
        if (++digit[w] < values[w].size()) break;
        digit[w] = 0;
      }
    }
  }
  for (const std::string& flag : at) {
    const std::string context = flag_context("--at", flag);
    std::vector<double> pose(axes.size(), 0.0);
    std::vector<bool> named(axes.size(), false);
    for (const auto& [index, text] : axis_items(desc, axes, flag, context, kAtForm)) {
      if (text.find(':') != std::string::npos) {
        fail(context, "--at takes one value per axis; ranges (start:stop:count) go in --grid");
      }
      pose[index] = axis_value(axes[index], text, context);
      named[index] = true;
    }
    // A pose names every axis: an axis left out is a mistake more often than a wish for 0.
    std::vector<std::string> missing, example;
    for (std::size_t i = 0; i < axes.size(); ++i) {
      if (named[i]) continue;
      const Axis& a = axes[i];
      missing.push_back(a.name);
      const bool zero_ok = !a.has_range() || (a.min <= 0 && 0 <= a.max);
      example.push_back(a.name + "=" + format_number(zero_ok ? 0 : 0.5 * (a.min + a.max)));
    }
    if (!missing.empty()) {
      std::string example_text;
      for (const std::string& e : example) example_text += (example_text.empty() ? "" : ",") + e;
      fail(context, std::string(missing.size() > 1 ? "axes " : "axis ") + join(missing) +
                        (missing.size() > 1 ? " are" : " is") +
                        " not given: --at names every "
                        "axis (" +
                        axes_list(desc, axes) + "); add e.g. " + example_text);
    }
    set.poses.push_back(std::move(pose));
  }
  return set;
}

std::vector<std::pair<std::size_t, std::vector<double>>> parse_axis_values(
    const Description& desc, const std::string& flag, const std::string& text) {
  const std::vector<Axis> axes = machine_axes(desc);
  const std::string context = flag_context(flag, text);
  std::vector<std::pair<std::size_t, std::vector<double>>> out;
  for (const auto& [index, value] : axis_items(desc, axes, text, context, kGridForm))
    out.emplace_back(index, grid_axis_values(axes[index], value, context));
  return out;
}

// ---- Outputs and tolerances -------------------------------------------------------------------

std::vector<OutputTolerance> parse_tolerances(const std::vector<std::string>& flags) {
  std::vector<OutputTolerance> out;
  const std::string form = "OUTPUT=value, e.g. dx=0.03mm or da=20urad";
  for (const std::string& flag : flags) {
    const std::string context = flag_context("--tolerance", flag);
    if (trim(flag).empty()) fail(context, "empty (expected " + form + ")");
    for (const std::string& raw : split(flag, ',')) {
      const std::string item = trim(raw);
      if (item.empty()) fail(context, "empty item (expected " + form + ")");
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos) {
        fail(context, quoted(abbreviated(item)) + " is not OUTPUT=value (expected " + form + ")");
      }
      OutputId id;
      try {
        id = parse_output(item.substr(0, eq));
      } catch (const std::invalid_argument& ex) {
        fail(context, ex.what());
      }
      const std::string text = trim(item.substr(eq + 1));
      const Quantity q = parse_quantity_unit(text, output_unit(id), context);
      const bool angle = output_is_angle(id);
      if (q.unit.angle != angle) {
        fail(context, std::string(output_name(id)) + " is " +
                          (angle ? "an orientation (rad) and needs an angle unit"
                                 : "a position (mm) and needs a length unit") +
                          ", got \"" + q.unit_name + "\"");
      }
      if (!(q.value() > 0)) fail(context, "a tolerance must be > 0, got " + text);
      for (const OutputTolerance& t : out) {
        if (t.output == id) {
          fail(context,
               std::string(output_name(id)) + " is given twice (" + t.text + " and " + text + ")");
        }
      }
      out.push_back({id, q.value(), text});
    }
  }
  return out;
}

// ---- Error distributions ----------------------------------------------------------------------

std::optional<InputDistribution> machine_distribution(const ErrorDef& err) {
  return to_base_distribution(err.distribution, error_to_base(err));
}

namespace {

struct SetKind {
  const char* name;
  std::size_t count;
  const char* form;
};

const std::vector<SetKind>& set_kinds() {
  static const std::vector<SetKind> kinds = {{"sigma", 1, "sigma"},
                                             {"normal", 2, "mean,sigma"},
                                             {"uniform", 2, "lo,hi"},
                                             {"truncnormal", 4, "mean,sigma,lo,hi"},
                                             {"const", 1, "value"}};
  return kinds;
}

std::string set_kind_names() {
  std::vector<std::string> names;
  for (const SetKind& k : set_kinds()) names.push_back(k.name);
  return join(names);
}

const char* const kSetForm =
    "NAME=KIND:VALUES, e.g. E_XX=sigma:5um, E_XX=normal:0,0.005mm, E_XX=uniform:-10,10um, "
    "E_XX=truncnormal:0,5,-10,10um, E_XX=const:2um, group:straightness=sigma:2um";

}  // namespace

std::vector<ErrorTarget> select_errors(const Description& desc, const std::string& name,
                                       const std::string& context) {
  std::vector<ErrorTarget> targets;
  if (name.compare(0, 6, "group:") == 0) {
    const std::string group = trim(name.substr(6));
    for (std::size_t i = 0; i < desc.errors.size(); ++i) {
      if (desc.errors[i].group == group) targets.push_back({i, 1});
    }
    if (targets.empty()) {
      fail(context, "no errors in group " + quoted(group) + " (groups with errors in machine " +
                        desc.name + ": " + join(used_groups(desc)) + ")");
    }
    return targets;
  }
  if (name.compare(0, 5, "axis:") == 0) {
    // Every error of the body an axis moves: its motion errors, and the location and squareness
    // errors the machine file places on it.
    const std::string axis = trim(name.substr(5));
    std::vector<std::string> axes;
    for (int b : desc.axes()) {
      const std::string& c = desc.bodies[static_cast<std::size_t>(b)].joint.coordinate;
      axes.push_back(c);
      if (c != axis) continue;
      for (std::size_t i = 0; i < desc.errors.size(); ++i)
        if (desc.errors[i].body == b) targets.push_back({i, 1});
    }
    if (std::find(axes.begin(), axes.end(), axis) == axes.end())
      fail(context, "unknown axis " + quoted(abbreviated(axis)) + " (machine " + desc.name +
                        " has axes " + join(axes) + ")");
    if (targets.empty()) fail(context, "axis " + axis + " has no errors in machine " + desc.name);
    return targets;
  }
  const int index = desc.error_index(name);
  if (index < 0) {
    fail(context, "unknown error " + quoted(abbreviated(name)) + " (machine " + desc.name +
                      " has " + join(error_names(desc)) + "; or group:<group>, axis:<axis>)");
  }
  int sign = 1;
  for (const Alias& a : desc.errors[static_cast<std::size_t>(index)].aliases) {
    if (a.name == name) sign = a.sign;
  }
  targets.push_back({static_cast<std::size_t>(index), sign});
  return targets;
}

void apply_set_flag(const Description& desc, const std::string& flag,
                    std::vector<std::optional<InputDistribution>>& dists) {
  const std::string context = flag_context("--set", flag);
  const std::size_t eq = flag.find('=');
  if (eq == std::string::npos) fail(context, "expected " + std::string(kSetForm));
  const std::string name = trim(flag.substr(0, eq));
  const std::string spec = trim(flag.substr(eq + 1));

  const std::vector<ErrorTarget> targets = select_errors(desc, name, context);

  const std::size_t colon = spec.find(':');
  if (colon == std::string::npos) {
    fail(context,
         "expected KIND:VALUES after '=' (kinds: " + set_kind_names() + "; " + kSetForm + ")");
  }
  const std::string kind_name = lower(trim(spec.substr(0, colon)));
  const SetKind* kind = nullptr;
  for (const SetKind& k : set_kinds()) {
    if (kind_name == k.name) kind = &k;
  }
  if (!kind) {
    fail(context, "unknown distribution " + quoted(trim(spec.substr(0, colon))) + " (expected " +
                      set_kind_names() + ")");
  }
  const std::vector<std::string> texts = split(spec.substr(colon + 1), ',');
  if (texts.size() != kind->count) {
    fail(context, std::string(kind->name) + " takes " + std::to_string(kind->count) +
                      (kind->count == 1 ? " number (" : " numbers (") + kind->form + "), got " +
                      std::to_string(texts.size()));
  }
  // Numbers without a unit take the last number's unit, else the error's declared unit: parse
  // with a placeholder default to learn which numbers carry one.
  std::vector<Quantity> given;
  for (const std::string& t : texts) given.push_back(parse_quantity_unit(t, "mm", context));
  const Quantity& last = given.back();

  for (const auto& [error, sign] : targets) {
    const ErrorDef& err = desc.errors[error];
    const bool rotation = err.effect == ErrorEffect::Rotation;
    std::vector<double> v;  // base units
    for (std::size_t k = 0; k < given.size(); ++k) {
      const Quantity& q = given[k];
      if (q.unit_given && q.unit.angle != rotation) {
        fail(context, "unit \"" + q.unit_name + "\" is " +
                          (q.unit.angle ? "an angle" : "a length") + " but error " + err.name +
                          " is a " + (rotation ? "rotation" : "translation"));
      }
      const double to_base = q.unit_given
                                 ? q.unit.to_base
                                 : (last.unit_given ? last.unit.to_base : error_to_base(err));
      v.push_back(q.number * to_base);
    }
    const std::string k = kind->name;
    const auto positive_sigma = [&](double s, const std::string& text) {
      if (!(s > 0)) {
        fail(context, "sigma must be > 0, got " + trim(text) +
                          (k == "const" ? "" : " (for a fixed value use const:VALUE)"));
      }
    };
    const auto ordered = [&](double lo, double hi) {
      if (!(lo < hi)) {
        fail(context, "lo (" + trim(texts[texts.size() - 2]) + ") must be less than hi (" +
                          trim(texts.back()) + ")");
      }
    };
    std::optional<InputDistribution> d;
    try {
      if (k == "sigma") {
        positive_sigma(v[0], texts[0]);
        d = InputDistribution::normal(0, v[0]);
      } else if (k == "normal") {
        positive_sigma(v[1], texts[1]);
        d = InputDistribution::normal(v[0], v[1]);
      } else if (k == "uniform") {
        ordered(v[0], v[1]);
        d = InputDistribution::uniform(v[0], v[1]);
      } else if (k == "truncnormal") {
        positive_sigma(v[1], texts[1]);
        ordered(v[2], v[3]);
        d = InputDistribution::truncated_normal(v[0], v[1], v[2], v[3]);
      } else {
        d = InputDistribution::normal(v[0], 0);
      }
    } catch (const std::invalid_argument& ex) {
      const std::string what = ex.what();
      if (what.rfind(context, 0) == 0) throw;
      fail(context, "invalid distribution: " + what);
    }
    dists[error] = sign < 0 ? negated(*d) : *d;
  }
}

std::vector<InputDistribution> error_distributions(const Description& desc,
                                                   const std::vector<std::string>& tolerance_files,
                                                   const std::vector<std::string>& set_flags) {
  std::vector<std::optional<InputDistribution>> dists(desc.errors.size());
  for (std::size_t i = 0; i < desc.errors.size(); ++i) {
    try {
      dists[i] = machine_distribution(desc.errors[i]);
    } catch (const std::invalid_argument& ex) {
      throw InputError(desc.errors[i].loc,
                       desc.errors[i].name + ": invalid distribution: " + ex.what());
    }
  }
  for (const std::string& file : tolerance_files) {
    const ToleranceOverrides o = read_tolerance_file(file, desc);
    for (std::size_t i = 0; i < o.size(); ++i) {
      if (o[i]) dists[i] = o[i];
    }
  }
  for (const std::string& flag : set_flags) apply_set_flag(desc, flag, dists);
  std::vector<std::string> missing;
  for (std::size_t i = 0; i < dists.size(); ++i) {
    if (!dists[i]) missing.push_back(desc.errors[i].name);
  }
  if (!missing.empty()) {
    throw std::invalid_argument(join(missing) + (missing.size() == 1 ? " has" : " have") +
                                " no distribution: give one in the machine file, a tolerance "
                                "file or --set");
  }
  std::vector<InputDistribution> out;
  out.reserve(dists.size());
  for (const auto& d : dists) out.push_back(*d);
  return out;
}

}  // namespace weilgen
