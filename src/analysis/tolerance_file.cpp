#include "weilgen/analysis/tolerance_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/expr.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace weilgen {
namespace {

const std::vector<std::string> kTopKeys = {"weilgen_tolerances", "machine", "groups", "errors"};
const std::vector<std::string> kEntryKeys = {"sigma",       "normal", "uniform",
                                             "truncnormal", "const",  "unit"};

// An error an entry applies to, and the sign of the name it was given by (alias sign).
struct Target {
  std::size_t error;
  int sign;
};

struct Item {
  std::string key;
  YAML::Node key_node;
  YAML::Node value;
  YAML::Node where;  // the value, or the key when the value is null (no position of its own)
  std::string path;
};

class Reader {
 public:
  Reader(std::string file, const Description& desc) : file_(std::move(file)), desc_(desc) {}

  ToleranceOverrides read(const YAML::Node& root) {
    if (!root.IsMap()) {
      throw InputError({file_, 1, 1},
                       "a tolerance file is a YAML mapping (weilgen_tolerances: 1, machine, "
                       "groups, errors)");
    }
    const std::vector<Item> top = entries(root, root, "", kTopKeys);
    const Item* version = find(top, "weilgen_tolerances");
    if (!version) {
      throw InputError({file_, 1, 1},
                       "missing required key 'weilgen_tolerances' (a tolerance file starts with "
                       "weilgen_tolerances: 1)");
    }
    const std::string v = version->value.IsScalar() ? version->value.Scalar() : "?";
    if (v != "1") {
      fail(version->where, version->path,
           "unsupported format version '" + v + "' (this weilgen reads weilgen_tolerances: 1)");
    }
    if (const Item* m = find(top, "machine")) {
      const std::string name = text(*m);
      if (name != desc_.name) {
        fail(m->where, m->path,
             "this file is for machine '" + name + "', not '" + desc_.name + "'");
      }
    }
    ToleranceOverrides out(desc_.errors.size());
    // Groups first, so that errors entries override them wherever they are written.
    if (const Item* g = find(top, "groups")) read_groups(*g, out);
    if (const Item* e = find(top, "errors")) read_errors(*e, out);
    return out;
  }

 private:
  SourceLoc loc(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    if (m.is_null() || m.line < 0) return {file_, 0, 0};
    return {file_, m.line + 1, m.column + 1};
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& path,
                         const std::string& message) const {
    throw InputError(loc(at), path.empty() ? message : path + ": " + message);
  }

  static const Item* find(const std::vector<Item>& items, const std::string& key) {
    for (const Item& i : items) {
      if (i.key == key) return &i;
    }
    return nullptr;
  }

  // A mapping (null reads as empty) with unique scalar keys, among `allowed` when given.
  std::vector<Item> entries(const YAML::Node& node, const YAML::Node& where,
                            const std::string& path, const std::vector<std::string>& allowed,
                            const std::string& expected = "a mapping") const {
    std::vector<Item> out;
    if (node.IsNull()) return out;
    if (!node.IsMap()) fail(where, path, "expected " + expected);
    for (auto it = node.begin(); it != node.end(); ++it) {
      const YAML::Node key = it->first;
      if (!key.IsScalar()) fail(key, path, "expected a key");
      const std::string name = key.Scalar();
      if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
        fail(key, path, "unknown key '" + name + "' (allowed: " + join(allowed) + ")");
      }
      if (const Item* first = find(out, name)) {
        fail(key, path,
             "duplicate key '" + name + "' (first at line " +
                 std::to_string(loc(first->key_node).line) + ")");
      }
      const YAML::Node value = it->second;
      out.push_back({name, key, value, value.IsNull() ? key : value,
                     path.empty() ? name : path + "." + name});
    }
    return out;
  }

  std::string text(const Item& i) const {
    if (!i.value.IsScalar()) fail(i.where, i.path, "expected a single value");
    return i.value.Scalar();
  }

  // A number or a parameter-free expression ("0.05/6").
  double number(const Item& i) const {
    const std::string s = text(i);
    std::string bare = lower(s);
    bare.erase(0, bare.find_first_not_of("+-."));
    if (bare == "nan") fail(i.where, i.path, "NaN is not a valid value");
    Expr e;
    try {
      e = parse_expr(s);
    } catch (const std::invalid_argument& ex) {
      fail(i.where, i.path, ex.what());
    }
    if (!e.params().empty()) {
      fail(i.where, i.path, "expected a number, got '" + s + "' (write the unit under 'unit')");
    }
    const double v = e.eval({});
    if (!std::isfinite(v)) fail(i.where, i.path, "'" + s + "' is not a finite number");
    return v;
  }

  void read_groups(const Item& groups, ToleranceOverrides& out) const {
    const std::vector<std::string> used = used_groups(desc_);
    for (const Item& g : entries(groups.value, groups.where, groups.path, {},
                                 "a mapping from group name to distribution")) {
      if (std::find(desc_.groups.begin(), desc_.groups.end(), g.key) == desc_.groups.end()) {
        fail(g.key_node, groups.path,
             "unknown group '" + g.key + "' (groups of machine " + desc_.name +
                 " with errors: " + join(used) + ")");
      }
      if (std::find(used.begin(), used.end(), g.key) == used.end()) {
        fail(g.key_node, groups.path,
             "group '" + g.key + "' has no errors in machine " + desc_.name +
                 " (groups with errors: " + join(used) + ")");
      }
      std::vector<Target> targets;
      for (std::size_t i = 0; i < desc_.errors.size(); ++i) {
        if (desc_.errors[i].group == g.key) targets.push_back({i, 1});
      }
      read_entry(g, targets, out);
    }
  }

  void read_errors(const Item& errors, ToleranceOverrides& out) const {
    std::vector<const Item*> seen(desc_.errors.size(), nullptr);
    const std::vector<Item> items = entries(errors.value, errors.where, errors.path, {},
                                            "a mapping from error name to distribution");
    for (const Item& e : items) {
      const int index = desc_.error_index(e.key);
      if (index < 0) {
        fail(e.key_node, errors.path,
             "unknown error '" + e.key + "' (machine " + desc_.name + " has " +
                 join(error_names(desc_)) + ")");
      }
      const auto i = static_cast<std::size_t>(index);
      if (const Item* first = seen[i]) {
        fail(e.key_node, errors.path,
             "error " + desc_.errors[i].name + " is given twice: as '" + first->key + "' (line " +
                 std::to_string(loc(first->key_node).line) + ") and as '" + e.key + "'");
      }
      seen[i] = &e;
      int sign = 1;
      for (const Alias& a : desc_.errors[i].aliases) {
        if (a.name == e.key) sign = a.sign;
      }
      read_entry(e, {{i, sign}}, out);
    }
  }

  // {sigma|normal|uniform|truncnormal|const: ..., unit: u} applied to every target.
  void read_entry(const Item& entry, const std::vector<Target>& targets,
                  ToleranceOverrides& out) const {
    if (!entry.value.IsMap()) {
      fail(entry.where, entry.path,
           "expected a distribution such as {sigma: 2, unit: um} (sigma, normal, uniform, "
           "truncnormal or const, and unit)");
    }
    const std::vector<Item> keys = entries(entry.value, entry.where, entry.path, kEntryKeys);
    std::optional<UnitFactor> unit;
    const Item* unit_item = find(keys, "unit");
    if (unit_item) {
      try {
        unit = parse_unit(text(*unit_item));
      } catch (const std::invalid_argument& ex) {
        fail(unit_item->where, unit_item->path, ex.what());
      }
    }
    Distribution d = read_distribution_keys(entry.value, file_, entry.path);
    const Item* constant = find(keys, "const");
    if (constant) {
      if (d.kind != Distribution::Kind::None) {
        for (const Item& k : keys) {
          if (k.key != "const" && k.key != "unit") {
            fail(k.key_node, entry.path,
                 "give one distribution, not both 'const' and '" + k.key + "'");
          }
        }
      }
      d.kind = Distribution::Kind::Normal;
      d.a = number(*constant);
      d.b = 0;
    }
    if (d.kind == Distribution::Kind::None) {
      fail(entry.where, entry.path,
           "give a distribution (sigma, normal, uniform, truncnormal or const)");
    }
    for (const Target& t : targets) {
      const ErrorDef& err = desc_.errors[t.error];
      const bool rotation = err.effect == ErrorEffect::Rotation;
      if (unit && unit->angle != rotation) {
        fail(unit_item->where, unit_item->path,
             "unit '" + text(*unit_item) + "' is " + (unit->angle ? "an angle" : "a length") +
                 " but error '" + err.name + "' is a " + (rotation ? "rotation" : "translation"));
      }
      std::optional<InputDistribution> base;
      try {
        base = to_base_distribution(d, unit ? unit->to_base : error_to_base(err));
      } catch (const std::invalid_argument& ex) {
        fail(entry.where, entry.path, std::string("invalid distribution: ") + ex.what());
      }
      out[t.error] = t.sign < 0 ? negated(*base) : *base;
    }
  }

  std::string file_;
  const Description& desc_;
};

// A base-unit value in the unit with factor `to_base`: the fewest digits that read back (times
// to_base) within 1e-15 relative, so 0.06/6000 rad prints as 1e-05, not 9.999999999999999e-06.
std::string in_unit(double base, double to_base) {
  if (base == 0) return "0";
  const double v = base / to_base;
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    const double back = std::strtod(buf, nullptr) * to_base;
    if (back == base || std::abs(back - base) <= 1e-15 * std::abs(base)) break;
  }
  return buf;
}

// One entry of the writer: "{sigma: 5, unit: um}".
std::string entry_text(const InputDistribution& base, const ErrorDef& err) {
  const double t = error_to_base(err);
  const auto n = [t](double v) { return in_unit(v, t); };
  std::string body;
  switch (base.kind()) {
    case InputDistribution::Kind::Normal:
      if (base.b() == 0) {
        body = "const: " + n(base.a());
      } else if (base.a() == 0) {
        body = "sigma: " + n(base.b());
      } else {
        body = "normal: [" + n(base.a()) + ", " + n(base.b()) + "]";
      }
      break;
    case InputDistribution::Kind::Uniform:
      body = base.lo() == base.hi() ? "const: " + n(base.lo())
                                    : "uniform: [" + n(base.lo()) + ", " + n(base.hi()) + "]";
      break;
    case InputDistribution::Kind::TruncatedNormal:
      body = base.b() == 0 ? "const: " + n(base.a())
                           : "truncnormal: [" + n(base.a()) + ", " + n(base.b()) + ", " +
                                 n(base.lo()) + ", " + n(base.hi()) + "]";
      break;
  }
  return "{" + body + ", unit: " + err.unit + "}";
}

}  // namespace

double error_to_base(const ErrorDef& err) {
  try {
    return parse_unit(err.unit).to_base;
  } catch (const std::invalid_argument&) {
    return err.to_base;
  }
}

std::optional<InputDistribution> to_base_distribution(const Distribution& d, double to_base) {
  switch (d.kind) {
    case Distribution::Kind::None:
      return std::nullopt;
    case Distribution::Kind::Normal:
      return InputDistribution::normal(d.a * to_base, d.b * to_base);
    case Distribution::Kind::Uniform:
      return InputDistribution::uniform(d.a * to_base, d.b * to_base);
    case Distribution::Kind::TruncatedNormal:
      return InputDistribution::truncated_normal(d.a * to_base, d.b * to_base, d.lo * to_base,
                                                 d.hi * to_base);
  }
  return std::nullopt;
}

InputDistribution negated(const InputDistribution& d) {
  switch (d.kind()) {
    case InputDistribution::Kind::Normal:
      return InputDistribution::normal(-d.a(), d.b());
    case InputDistribution::Kind::Uniform:
      return InputDistribution::uniform(-d.hi(), -d.lo());
    case InputDistribution::Kind::TruncatedNormal:
      return InputDistribution::truncated_normal(-d.a(), d.b(), -d.hi(), -d.lo());
  }
  return d;
}

ToleranceOverrides read_tolerance_text(const std::string& yaml, const std::string& filename,
                                       const Description& desc) {
  const YAML::Node root = parse_yaml(yaml, filename);
  return Reader(filename, desc).read(root);
}

ToleranceOverrides read_tolerance_file(const std::string& path, const Description& desc) {
  std::string text;
  if (const std::string why = unreadable_reason(path); !why.empty() || !read_file(path, text))
    throw InputError({path, 0, 0},
                     "cannot read the tolerance file: " + (why.empty() ? "read error" : why));
  return read_tolerance_text(text, path, desc);
}

std::vector<double> read_error_values(const std::string& path, const Description& desc) {
  std::string text;
  if (!read_file(path, text)) throw InputError({path, 0, 0}, "cannot read the error values");
  const ToleranceOverrides o = read_tolerance_text(text, path, desc);
  std::vector<double> values(desc.errors.size(), 0.0);
  for (std::size_t i = 0; i < o.size(); ++i) {
    if (!o[i]) continue;
    if (!o[i]->is_constant()) {
      // The entry's line: the first line naming the error or one of its aliases.
      int line = 0, n = 0;
      std::istringstream in(text);
      for (std::string l; line == 0 && std::getline(in, l);) {
        ++n;
        if (l.find(desc.errors[i].name) != std::string::npos) line = n;
        for (const auto& a : desc.errors[i].aliases)
          if (line == 0 && l.find(a.name) != std::string::npos) line = n;
        if (line == 0 && l.find("group:") == std::string::npos &&
            l.find(desc.errors[i].group) != std::string::npos)
          line = n;  // set through its group
      }
      throw InputError({path, line, 0}, desc.errors[i].name +
                                            ": a distribution, but a compensation needs a value: "
                                            "write {const: v, unit: ...}");
    }
    values[i] = o[i]->mean();
  }
  return values;
}

std::string tolerance_file_text(const Description& desc,
                                const std::vector<InputDistribution>& base_unit_distributions,
                                const std::string& header_comment) {
  if (base_unit_distributions.size() != desc.errors.size()) {
    throw std::invalid_argument("tolerance file for machine " + desc.name + ": " +
                                std::to_string(base_unit_distributions.size()) +
                                " distributions given for " + std::to_string(desc.errors.size()) +
                                " errors");
  }
  std::ostringstream out;
  if (!header_comment.empty()) {
    for (const std::string& line : split(header_comment, '\n')) {
      out << (line.empty() ? "#" : "# " + line) << "\n";
    }
  }
  out << "weilgen_tolerances: 1\n";
  out << "machine: " << desc.name << "\n";
  if (desc.errors.empty()) {
    out << "errors: {}\n";
    return out.str();
  }
  out << "errors:  # values in each error's unit\n";
  std::vector<std::string> lines;
  std::size_t width = 0;
  for (std::size_t i = 0; i < desc.errors.size(); ++i) {
    const ErrorDef& err = desc.errors[i];
    lines.push_back("  " + err.name + ": " + entry_text(base_unit_distributions[i], err));
    width = std::max(width, lines.back().size());
  }
  for (std::size_t i = 0; i < desc.errors.size(); ++i) {
    const ErrorDef& err = desc.errors[i];
    std::string comment = err.group;
    for (const Alias& a : err.aliases) {
      comment += std::string(", ") + (a.sign < 0 ? "-" : "") + a.name;
    }
    out << lines[i] << std::string(width - lines[i].size(), ' ') << "  # " << comment << "\n";
  }
  return out.str();
}

void write_tolerance_file(const std::string& path, const Description& desc,
                          const std::vector<InputDistribution>& base_unit_distributions,
                          const std::string& header_comment) {
  write_file_atomically(path, tolerance_file_text(desc, base_unit_distributions, header_comment));
}

}  // namespace weilgen
