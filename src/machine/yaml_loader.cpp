#include "weilgen/machine/yaml_loader.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>

#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/derived.hpp"
#include "weilgen/machine/iso_names.hpp"
#include "weilgen/machine/model_key.hpp"
#include "weilgen/machine/pdge_basis.hpp"

#ifndef WEILGEN_MACHINES_DIR
#define WEILGEN_MACHINES_DIR "machines"
#endif

namespace weilgen {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Unit {
  const char* name;
  double to_base;
  bool angle;
};

const std::vector<Unit> kErrorUnits = {{"mm", 1, false},
                                       {"um", 1e-3, false},
                                       {"nm", 1e-6, false},
                                       {"rad", 1, true},
                                       {"mrad", 1e-3, true},
                                       {"urad", 1e-6, true},
                                       {"arcsec", kPi / 648000, true},
                                       {"deg", kPi / 180, true}};
const std::vector<Unit> kPrismaticUnits = {
    {"mm", 1, false}, {"um", 1e-3, false}, {"m", 1e3, false}};
const std::vector<Unit> kRevoluteUnits = {{"deg", kPi / 180, true}, {"rad", 1, true}};
const std::vector<Unit> kParameterUnits = {{"mm", 1, false}, {"deg", 1, true}};

const std::vector<std::string> kTopKeys = {"weilgen", "name",       "title",     "notes",
                                           "algebra", "parameters", "groups",    "error_defaults",
                                           "bodies",  "tool",       "workpiece", "points",
                                           "derived", "output",     "pdge_basis"};
const std::vector<std::string> kBodyKeys = {"parent", "offset", "joint", "errors"};
const std::vector<std::string> kOffsetKeys = {"translation", "rotation"};
const std::vector<std::string> kRotationKeys = {"axis", "angle"};
const std::vector<std::string> kJointKeys = {"type",       "axis", "twist", "through",
                                             "coordinate", "unit", "range", "linked"};
const std::vector<std::string> kDerivedKeys = {"value", "description"};
const std::vector<std::string> kOutputKeys = {"transform", "point", "description"};
const std::vector<std::string> kStepKeys = {"translate", "twist", "by"};
const std::vector<std::string> kDistributionKeys = {"sigma", "normal", "uniform", "truncnormal"};
const std::vector<std::string> kErrorKeys = {
    "aliases",     "group", "unit",   "dependence", "effect",      "direction", "placement",
    "description", "sigma", "normal", "uniform",    "truncnormal", "basis"};
const std::vector<std::string> kDefaultKeys = {"sigma", "normal", "uniform", "truncnormal", "unit"};
const std::vector<std::string> kParameterKeys = {"value", "unit", "description"};
const std::vector<std::string> kPointKeys = {"body", "point"};
const std::vector<std::string> kAlgebraKeys = {"order", "relations"};
const std::vector<std::string> kAliasKeys = {"name", "sign"};

std::string unit_names(const std::vector<Unit>& units) {
  std::vector<std::string> names;
  for (const Unit& u : units) names.push_back(u.name);
  return join(names);
}

const Unit* find_unit(const std::vector<Unit>& units, const std::string& name) {
  for (const Unit& u : units) {
    if (name == u.name) return &u;
  }
  return nullptr;
}

bool is_identifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

// A value to read, the node to point at when it is wrong (a null value has no useful position of
// its own, so its key stands in), and its name in messages ("bodies.x.joint.axis").
struct Field {
  YAML::Node node;
  YAML::Node where;
  std::string path;
};

struct Entry {
  std::string key;
  YAML::Node key_node;
  Field value;
};

struct MapView {
  Field self;
  std::vector<Entry> entries;

  const Entry* find(const std::string& key) const {
    for (const Entry& e : entries) {
      if (e.key == key) return &e;
    }
    return nullptr;
  }
};

std::string sub_path(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

// Default distribution of an error group (`error_defaults`).
struct GroupDefault {
  Distribution distribution;
  std::string unit;  // empty: values are in the error's unit
};

// A body while the file is read: its parent is still a name, indices are in file order.
struct BodyDraft {
  Body body;
  std::string parent_name;
  Field parent_field;
  YAML::Node key;
  std::string path;
};

// Who holds a name, for "already used" messages.
struct Claim {
  std::string kind;
  std::string owner;
  int line = 0;
};

class Loader {
 public:
  explicit Loader(std::string file) : file_(std::move(file)) {}

  Description load(const YAML::Node& root) {
    if (!root.IsMap()) {
      throw InputError({file_, 1, 1},
                       "a machine file is a YAML mapping (weilgen: 1, name, "
                       "bodies, tool, workpiece, ...)");
    }
    const MapView top = map({root, root, ""}, kTopKeys);
    read_version(required(top, "weilgen"));
    d_.name = identifier(required(top, "name").value, "machine name");
    if (const Entry* e = top.find("title")) d_.title = text(e->value);
    if (const Entry* e = top.find("notes")) d_.notes = text(e->value);
    d_.groups = builtin_groups();
    if (const Entry* e = top.find("parameters")) read_parameters(e->value);
    if (const Entry* e = top.find("groups")) read_groups(e->value);
    if (const Entry* e = top.find("error_defaults")) read_error_defaults(e->value);
    read_bodies(required(top, "bodies"));
    if (const Entry* e = top.find("points")) read_points(e->value);
    if (const Entry* e = top.find("derived")) read_derived(e->value);
    if (const Entry* e = top.find("output")) {
      for (const char* key : {"tool", "workpiece"}) {
        if (const Entry* t = top.find(key)) {
          fail_at(t->key_node, "",
                  std::string("'") + key +
                      "' does not apply: this machine's output is the 'output' transform");
        }
      }
      d_.output = read_output(e->value);
    } else {
      d_.tool = read_point_spec(required(top, "tool").value);
      d_.workpiece = read_point_spec(required(top, "workpiece").value);
    }
    if (const Entry* e = top.find("algebra")) read_algebra(e->value);
    if (const Entry* e = top.find("pdge_basis")) {
      d_.pdge_basis = basis_text(e->value);
      d_.pdge_basis_loc = loc(e->value.where);
    }
    d_.source_file = file_;
    check_derived(d_);
    return std::move(d_);
  }

  // A PDGE basis spelling (poly:3, fourier:2:20); checked here so a typo names its line.
  std::string basis_text(const Field& f) const {
    const std::string s = text(f);
    try {
      parse_basis(s);
    } catch (const std::invalid_argument& e) {
      fail(f, e.what());
    }
    return s;
  }

  // read_distribution_keys(): the distribution keys of any mapping, other keys ignored.
  Distribution distribution_keys(const YAML::Node& node, const std::string& path) const {
    return read_distribution(map({node, node, path}, {})).value_or(Distribution{});
  }

 private:
  // ---- Reporting and generic readers -------------------------------------------------------

  SourceLoc loc(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    if (m.is_null() || m.line < 0) return {file_, 0, 0};
    return {file_, m.line + 1, m.column + 1};
  }

  [[noreturn]] void fail(const Field& f, const std::string& message) const {
    throw InputError(loc(f.where), f.path.empty() ? message : f.path + ": " + message);
  }

  [[noreturn]] void fail_at(const YAML::Node& at, const std::string& path,
                            const std::string& message) const {
    fail({at, at, path}, message);
  }

  // A mapping (null reads as empty) whose keys are unique, scalar and among `allowed` (when given).
  MapView map(const Field& f, const std::vector<std::string>& allowed,
              const char* key_kind = "key") const {
    MapView m{f, {}};
    if (f.node.IsNull()) return m;
    if (!f.node.IsMap()) fail(f, "expected a mapping");
    for (auto it = f.node.begin(); it != f.node.end(); ++it) {
      const YAML::Node key = it->first;
      if (!key.IsScalar()) fail_at(key, f.path, std::string("expected a ") + key_kind);
      const std::string name = key.Scalar();
      if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
        fail_at(key, f.path, "unknown key '" + name + "' (allowed: " + join(allowed) + ")");
      }
      if (const Entry* first = m.find(name)) {
        fail_at(key, f.path,
                std::string("duplicate ") + key_kind + " '" + name + "' (first at line " +
                    std::to_string(loc(first->key_node).line) + ")");
      }
      const YAML::Node value = it->second;
      m.entries.push_back(
          {name, key, {value, value.IsNull() ? key : value, sub_path(f.path, name)}});
    }
    return m;
  }

  const Entry& required(const MapView& m, const std::string& key) const {
    if (const Entry* e = m.find(key)) return *e;
    fail(m.self, "missing required key '" + key + "'");
  }

  std::string text(const Field& f) const {
    if (!f.node.IsScalar()) fail(f, "expected a single value");
    return f.node.Scalar();
  }

  std::string identifier(const Field& f, const std::string& what) const {
    const std::string s = f.node.IsScalar() ? f.node.Scalar() : std::string();
    if (!is_identifier(s)) {
      fail(f, what + " '" + s + "' is not an identifier ([A-Za-z_][A-Za-z0-9_]*)");
    }
    return s;
  }

  std::string key_identifier(const Entry& e, const std::string& parent_path,
                             const std::string& what) const {
    return identifier({e.key_node, e.key_node, parent_path}, what);
  }

  std::vector<Field> items(const Field& f, size_t min, size_t max, const std::string& form) const {
    if (!f.node.IsSequence() || f.node.size() < min || f.node.size() > max) {
      fail(f, "expected " + form);
    }
    std::vector<Field> out;
    for (size_t i = 0; i < f.node.size(); ++i) {
      const YAML::Node n = f.node[i];
      out.push_back({n, n.IsNull() ? f.where : n, f.path + "[" + std::to_string(i) + "]"});
    }
    return out;
  }

  Expr parsed(const Field& f) const {
    const std::string s = text(f);
    std::string bare = lower(s);
    bare.erase(0, bare.find_first_not_of("+-."));
    if (bare == "nan") fail(f, "NaN is not a valid value");
    if (bare == "inf" || bare == "infinity") fail(f, "'" + s + "' is not a finite number");
    try {
      return parse_expr(s);
    } catch (const std::invalid_argument& ex) {
      fail(f, ex.what());
    }
  }

  double finite(const Field& f, double v) const {
    if (!std::isfinite(v)) fail(f, "'" + text(f) + "' is not a finite number");
    return v;
  }

  // A number, possibly written as an expression without parameters ("0.05/6").
  double number(const Field& f) const {
    const Expr e = parsed(f);
    const std::vector<std::string> names = e.params();
    if (!names.empty()) {
      fail(f, "expected a number, got '" + text(f) + "' (parameters such as '" + names[0] +
                  "' are allowed only in offsets, points and static angles)");
    }
    return finite(f, e.eval({}));
  }

  double positive(const Field& f, const std::string& what) const {
    const double v = number(f);
    if (v <= 0) fail(f, what + " must be positive, got " + text(f));
    return v;
  }

  // An expression over the declared parameters (offsets, points, static angles).
  Expr expression(const Field& f) const {
    const Expr e = parsed(f);
    for (const std::string& p : e.params()) {
      if (parameter_defaults_.count(p) == 0) {
        const std::string declared = parameter_defaults_.empty()
                                         ? "no parameters are declared"
                                         : "declared: " + join(parameter_names_);
        fail(f, "unknown parameter '" + p + "' in '" + text(f) + "' (" + declared + ")");
      }
    }
    finite(f, e.eval(parameter_defaults_));
    return e;
  }

  std::array<Expr, 3> point(const Field& f) const {
    const std::vector<Field> xyz = items(f, 3, 3, "[x, y, z]");
    return {expression(xyz[0]), expression(xyz[1]), expression(xyz[2])};
  }

  // x, -y, ... or [ax, ay, az], normalised.
  Vec3 direction(const Field& f) const {
    if (f.node.IsScalar()) {
      static const std::vector<std::pair<std::string, Vec3>> named = {
          {"x", {1, 0, 0}},   {"y", {0, 1, 0}},   {"z", {0, 0, 1}},
          {"-x", {-1, 0, 0}}, {"-y", {0, -1, 0}}, {"-z", {0, 0, -1}}};
      for (const auto& [name, v] : named) {
        if (f.node.Scalar() == name) return v;
      }
      fail(f, "unknown direction '" + f.node.Scalar() + "' (x, y, z, -x, -y, -z or [ax, ay, az])");
    }
    const std::vector<Field> xyz =
        items(f, 3, 3, "a direction: x, y, z, -x, -y, -z or [ax, ay, az]");
    Vec3 v{number(xyz[0]), number(xyz[1]), number(xyz[2])};
    const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (norm == 0) fail(f, "direction must not be zero");
    for (double& c : v) c /= norm;
    return v;
  }

  template <typename E>
  E choice(const Field& f, const std::vector<std::pair<std::string, E>>& options) const {
    const std::string s = f.node.IsScalar() ? f.node.Scalar() : std::string();
    std::vector<std::string> names;
    for (const auto& [name, value] : options) {
      if (s == name) return value;
      names.push_back(name);
    }
    fail(f, "unknown value '" + s + "' (allowed: " + join(names) + ")");
  }

  // Registers `name` in `names`, failing when another holder already has it.
  void claim(std::map<std::string, Claim>& names, const std::string& name, const Claim& holder,
             const Field& at) const {
    const auto [it, inserted] = names.emplace(name, holder);
    if (inserted) return;
    const Claim& first = it->second;
    const std::string line = std::to_string(first.line);
    if (first.kind == holder.kind && holder.kind != "alias") {
      fail(at, "duplicate " + holder.kind + " '" + name + "' (first at line " + line + ")");
    }
    if (first.kind == "alias" || holder.kind == "alias") {
      const std::string what =
          first.kind == "alias" ? "an alias of error " + first.owner : "an error name";
      fail(at, "duplicate " + holder.kind + " '" + name + "': already used as " + what +
                   " at line " + line);
    }
    fail(at, "'" + name + "' is already the name of a " + first.kind + " (line " + line +
                 "); parameters, coordinates and error names must be distinct");
  }

  // Parameters, coordinates and error names are all symbols of the generated model.
  void claim_symbol(const std::string& name, const std::string& kind, const Field& at) {
    claim(symbols_, name, {kind, "", loc(at.where).line}, at);
  }

  // ---- Top-level sections --------------------------------------------------------------------

  void read_version(const Entry& e) {
    if (!e.value.node.IsScalar() || e.value.node.Scalar() != "1") {
      const std::string got = e.value.node.IsScalar() ? e.value.node.Scalar() : "?";
      fail(e.value, "unsupported format version '" + got + "' (this weilgen reads weilgen: 1)");
    }
  }

  void read_parameters(const Field& f) {
    const MapView m = map(f, {}, "parameter name");
    for (const Entry& e : m.entries) {
      Parameter p;
      p.name = key_identifier(e, f.path, "parameter name");
      if (p.name == "pi") fail_at(e.key_node, f.path, "'pi' is reserved and cannot be a parameter");
      claim_symbol(p.name, "parameter", {e.key_node, e.key_node, f.path});
      p.unit = "mm";
      if (e.value.node.IsMap()) {
        const MapView pm = map(e.value, kParameterKeys);
        p.value = number(required(pm, "value").value);
        if (const Entry* u = pm.find("unit")) p.unit = unit(u->value, kParameterUnits)->name;
        if (const Entry* t = pm.find("description")) p.description = text(t->value);
      } else {
        p.value = number(e.value);
      }
      parameter_defaults_[p.name] = p.value;
      parameter_names_.push_back(p.name);
      d_.parameters.push_back(std::move(p));
    }
  }

  const Unit* unit(const Field& f, const std::vector<Unit>& units) const {
    const std::string s = text(f);
    const Unit* u = find_unit(units, s);
    if (!u) fail(f, "unknown unit '" + s + "' (allowed: " + unit_names(units) + ")");
    return u;
  }

  void read_groups(const Field& f) {
    for (const Field& item : items(f, 0, SIZE_MAX, "a list of group names")) {
      const std::string g = identifier(item, "group name");
      // Re-declaring a built-in group is harmless (the README's own example does).
      if (!has_group(g)) d_.groups.push_back(g);
    }
  }

  bool has_group(const std::string& g) const {
    return std::find(d_.groups.begin(), d_.groups.end(), g) != d_.groups.end();
  }

  std::string known_group(const Field& f) const {
    const std::string g = text(f);
    if (!has_group(g)) {
      fail(f, "unknown group '" + g + "' (known: " + join(d_.groups) +
                  "; declare more under 'groups:')");
    }
    return g;
  }

  void read_error_defaults(const Field& f) {
    const MapView m = map(f, {}, "group");
    for (const Entry& e : m.entries) {
      const std::string group = known_group({e.key_node, e.key_node, f.path});
      const MapView dm = map(e.value, kDefaultKeys);
      GroupDefault def;
      const std::optional<Distribution> dist = read_distribution(dm);
      if (!dist) fail(dm.self, "give a distribution (" + join(kDistributionKeys) + ")");
      def.distribution = *dist;
      if (const Entry* u = dm.find("unit")) def.unit = unit(u->value, kErrorUnits)->name;
      defaults_[group] = def;
      if (const Entry* u = dm.find("unit")) default_units_.emplace(group, u->value);
    }
  }

  // sigma | normal | uniform | truncnormal, at most one; values in the caller's unit.
  std::optional<Distribution> read_distribution(const MapView& m) const {
    const Entry* chosen = nullptr;
    for (const std::string& key : kDistributionKeys) {
      const Entry* e = m.find(key);
      if (!e) continue;
      if (chosen) {
        fail_at(e->key_node, m.self.path,
                "give one distribution, not both '" + chosen->key + "' and '" + key + "'");
      }
      chosen = e;
    }
    if (!chosen) return std::nullopt;
    const Field& f = chosen->value;
    Distribution d;
    if (chosen->key == "sigma") {
      d.kind = Distribution::Kind::Normal;
      d.b = positive(f, "sigma");
    } else if (chosen->key == "normal") {
      const std::vector<Field> v = items(f, 2, 2, "[mean, sigma]");
      d.kind = Distribution::Kind::Normal;
      d.a = number(v[0]);
      d.b = positive(v[1], "sigma");
    } else if (chosen->key == "uniform") {
      const std::vector<Field> v = items(f, 2, 2, "[lo, hi]");
      d.kind = Distribution::Kind::Uniform;
      d.a = d.lo = number(v[0]);
      d.b = d.hi = number(v[1]);
      check_interval(f, d.lo, d.hi);
    } else {
      const std::vector<Field> v = items(f, 4, 4, "[mean, sigma, lo, hi]");
      d.kind = Distribution::Kind::TruncatedNormal;
      d.a = number(v[0]);
      d.b = positive(v[1], "sigma");
      d.lo = number(v[2]);
      d.hi = number(v[3]);
      check_interval(f, d.lo, d.hi);
    }
    return d;
  }

  void check_interval(const Field& f, double lo, double hi) const {
    if (lo >= hi)
      fail(f, "lo (" + format_short(lo) + ") must be less than hi (" + format_short(hi) + ")");
  }

  // ---- Bodies ---------------------------------------------------------------------------------

  void read_bodies(const Entry& bodies) {
    const MapView m = map(bodies.value, {}, "body name");
    if (m.entries.empty()) fail(bodies.value, "no bodies");
    for (const Entry& e : m.entries) {
      BodyDraft draft;
      draft.body.name = key_identifier(e, m.self.path, "body name");
      draft.body.loc = loc(e.key_node);
      draft.key = e.key_node;
      draft.path = e.value.path;
      drafts_.push_back(std::move(draft));
    }
    for (size_t i = 0; i < m.entries.size(); ++i) read_body(static_cast<int>(i), m.entries[i]);
    link_parents();
    const int base = single_base(bodies);
    check_cycles(base);
    apply_order(tree_order(base));
  }

  void read_body(int b, const Entry& e) {
    const MapView m = map(e.value, kBodyKeys);
    if (const Entry* p = m.find("parent")) {
      drafts_[b].parent_name = identifier(p->value, "parent");
      drafts_[b].parent_field = p->value;
    }
    if (const Entry* o = m.find("offset")) drafts_[b].body.offset = read_offset(o->value);
    if (const Entry* j = m.find("joint")) {
      drafts_[b].body.joint = read_joint(*j);
      if (drafts_[b].parent_name.empty() && drafts_[b].body.joint.type != JointType::Fixed) {
        fail(j->value, "the base body (no parent) cannot have a moving joint");
      }
    }
    read_body_errors(b, m.find("errors"));
  }

  Offset read_offset(const Field& f) const {
    const MapView m = map(f, kOffsetKeys);
    Offset o;
    if (const Entry* t = m.find("translation")) o.translation = point(t->value);
    if (const Entry* r = m.find("rotation")) {
      for (const Field& item : items(r->value, 0, SIZE_MAX, "a list of {axis, angle}")) {
        const MapView rm = map(item, kRotationKeys);
        StaticRotation rot;
        rot.axis = direction(required(rm, "axis").value);
        rot.angle_deg = expression(required(rm, "angle").value);
        o.rotations.push_back(std::move(rot));
      }
    }
    return o;
  }

  Joint read_joint(const Entry& e) {
    const MapView m = map(e.value, kJointKeys);
    Joint j;
    j.loc = loc(e.key_node);
    const Entry* twist = m.find("twist");
    const Entry* type = m.find("type");
    if (!type && !twist)
      fail(m.self, "missing required key 'type' (or give the joint as a 'twist')");
    if (type) {
      j.type = choice<JointType>(type->value, {{"fixed", JointType::Fixed},
                                               {"prismatic", JointType::Prismatic},
                                               {"revolute", JointType::Revolute}});
    }
    if (type && j.type == JointType::Fixed) {
      for (const Entry& other : m.entries) {
        if (other.key != "type") {
          fail_at(other.key_node, m.self.path, "a fixed joint takes no '" + other.key + "'");
        }
      }
      return j;
    }
    if (twist) {
      for (const char* key : {"axis", "through"}) {
        if (const Entry* other = m.find(key)) {
          fail_at(other->key_node, m.self.path,
                  std::string("give either 'twist' or '") + key +
                      "', not both (a twist's v already places the axis)");
        }
      }
      read_twist(twist->value, type ? std::optional<JointType>(j.type) : std::nullopt, j);
    } else {
      j.axis = direction(required(m, "axis").value);
      if (const Entry* t = m.find("through")) {
        if (j.type != JointType::Revolute) {
          fail_at(t->key_node, m.self.path, "'through' places a revolute joint's axis line");
        }
        j.through = point(t->value);
      }
    }
    const Field& coordinate = required(m, "coordinate").value;
    j.coordinate = identifier(coordinate, "coordinate");
    claim_symbol(j.coordinate, "coordinate", coordinate);
    const std::vector<Unit>& units =
        j.type == JointType::Prismatic ? kPrismaticUnits : kRevoluteUnits;
    const Unit* u = &units.front();
    if (const Entry* ue = m.find("unit")) u = unit(ue->value, units);
    j.unit = u->name;
    j.to_base = u->to_base;
    const Entry* range = m.find("range");
    if (const Entry* l = m.find("linked")) {
      if (range) {
        fail_at(range->key_node, m.self.path,
                "a linked coordinate has no range of its own: it follows from 'linked'");
      }
      j.link = parsed(l->value);  // names are checked once all coordinates are known
    }
    if (range) {
      const std::vector<Field> v = items(range->value, 2, 2, "[min, max]");
      j.min = number(v[0]);
      j.max = number(v[1]);
      if (j.min > j.max)
        fail(range->value, "min " + text(v[0]) + " is greater than max " + text(v[1]));
    }
    return j;
  }

  // The six fields of a twist [ωx, ωy, ωz, vx, vy, vz] and its ω: numbers, a unit vector or zero.
  std::vector<Field> twist_fields(const Field& f, Vec3& w) const {
    std::vector<Field> xi = items(f, 6, 6, "a twist [wx, wy, wz, vx, vy, vz]");
    w = {number(xi[0]), number(xi[1]), number(xi[2])};
    const double wn = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (wn != 0 && std::abs(wn - 1) > 1e-9)
      fail(f, "w must be a unit vector or zero, |w| = " + format_short(wn));
    return xi;
  }

  // ξ = [ωx, ωy, ωz, vx, vy, vz] (the seed's twists): ω numbers, v expressions over parameters.
  void read_twist(const Field& f, std::optional<JointType> declared, Joint& j) const {
    Vec3 w;
    const std::vector<Field> xi = twist_fields(f, w);
    std::array<Expr, 3> v{expression(xi[3]), expression(xi[4]), expression(xi[5])};
    std::string textual;
    for (const Field& x : xi) textual += (textual.empty() ? "" : ", ") + text(x);
    j.twist = "[" + textual + "]";
    if (w == Vec3{0, 0, 0}) {
      j.type = JointType::Prismatic;
      for (const Expr& c : v) {
        if (!c.is_number()) {
          fail(f, "a prismatic twist (w = 0) has a unit direction v of numbers, not '" + c.str() +
                      "'");
        }
      }
      j.axis = {v[0].number, v[1].number, v[2].number};
      const double vn =
          std::sqrt(j.axis[0] * j.axis[0] + j.axis[1] * j.axis[1] + j.axis[2] * j.axis[2]);
      if (std::abs(vn - 1) > 1e-9) {
        fail(f, "a prismatic twist (w = 0) needs a unit v, |v| = " + format_short(vn) +
                    " (scale the coordinate's unit instead)");
      }
    } else {
      j.type = JointType::Revolute;
      j.axis = w;
      double pitch = 0;
      for (int i = 0; i < 3; ++i) pitch += w[i] * v[i].eval(parameter_defaults_);
      if (std::abs(pitch) > 1e-12) {
        fail(f, "screw joints are not supported: the pitch w·v = " + format_short(pitch) +
                    " mm/rad must be 0 (v = -w × q for an axis through q)");
      }
      // The axis passes through q = w × v (for w·v = 0, v = -w × q).
      j.through = {linear_combination({{w[1], v[2]}, {-w[2], v[1]}}),
                   linear_combination({{w[2], v[0]}, {-w[0], v[2]}}),
                   linear_combination({{w[0], v[1]}, {-w[1], v[0]}})};
    }
    if (declared && *declared != j.type) {
      fail(f, std::string("the twist describes a ") +
                  (j.type == JointType::Prismatic ? "prismatic" : "revolute") +
                  " joint, but 'type' says otherwise");
    }
  }

  // ---- Points, derived quantities, output transform ---------------------------------------

  void read_points(const Field& f) {
    const MapView m = map(f, {}, "point name");
    for (const Entry& e : m.entries) {
      ChainPoint p;
      p.name = key_identifier(e, f.path, "point name");
      claim_symbol(p.name, "chain point", {e.key_node, e.key_node, f.path});
      p.at = read_point_spec(e.value);
      d_.points.push_back(std::move(p));
    }
  }

  void read_derived(const Field& f) {
    const MapView m = map(f, {}, "quantity name");
    for (const Entry& e : m.entries) {
      Derived q;
      q.name = key_identifier(e, f.path, "derived quantity name");
      claim_symbol(q.name, "derived quantity", {e.key_node, e.key_node, f.path});
      if (e.value.node.IsMap()) {
        const MapView qm = map(e.value, kDerivedKeys);
        q.value = parsed(required(qm, "value").value);
        q.loc = loc(required(qm, "value").value.where);
        if (const Entry* t = qm.find("description")) q.description = text(t->value);
      } else {
        q.value = parsed(e.value);
        q.loc = loc(e.value.where);
      }
      d_.derived.push_back(std::move(q));
    }
  }

  OutputTransform read_output(const Field& f) const {
    const MapView m = map(f, kOutputKeys);
    OutputTransform out;
    out.loc = loc(f.where);
    for (const Field& item : items(required(m, "transform").value, 1, SIZE_MAX,
                                   "a list of {translate: [x, y, z]} and {twist: [...], by: q}")) {
      const MapView sm = map(item, kStepKeys);
      TransformStep step;
      step.loc = loc(item.where);
      if (const Entry* t = sm.find("translate")) {
        if (sm.entries.size() != 1) fail(item, "a translate step has no other keys");
        const std::vector<Field> xyz = items(t->value, 3, 3, "[x, y, z]");
        for (int i = 0; i < 3; ++i) step.translation[static_cast<size_t>(i)] = parsed(xyz[i]);
      } else if (const Entry* tw = sm.find("twist")) {
        step.kind = TransformStep::Kind::Twist;
        const std::vector<Field> xi = twist_fields(tw->value, step.omega);
        for (int i = 0; i < 3; ++i) step.v[static_cast<size_t>(i)] = parsed(xi[i + 3]);
        step.amount = parsed(required(sm, "by").value);
      } else {
        fail(item, "a step is {translate: [x, y, z]} or {twist: [wx, wy, wz, vx, vy, vz], by: q}");
      }
      out.steps.push_back(std::move(step));
    }
    out.point = point_formula(required(m, "point").value);
    if (const Entry* t = m.find("description")) out.description = text(t->value);
    return out;
  }

  // Names in output and derived expressions are resolved by check_derived() (machine/derived.hpp).
  std::array<Expr, 3> point_formula(const Field& f) const {
    const std::vector<Field> xyz = items(f, 3, 3, "[x, y, z]");
    return {parsed(xyz[0]), parsed(xyz[1]), parsed(xyz[2])};
  }

  // Parent names to indices (file order).
  void link_parents() {
    for (size_t i = 0; i < drafts_.size(); ++i) {
      BodyDraft& d = drafts_[i];
      if (d.parent_name.empty()) continue;
      d.body.parent = draft_index(d.parent_name);
      if (d.body.parent < 0) {
        fail(d.parent_field,
             "unknown parent '" + d.parent_name + "' (bodies: " + join(draft_names()) + ")");
      }
      if (d.body.parent == static_cast<int>(i)) {
        fail(d.parent_field, "body '" + d.body.name + "' cannot be its own parent");
      }
    }
  }

  int draft_index(const std::string& name) const {
    for (size_t i = 0; i < drafts_.size(); ++i) {
      if (drafts_[i].body.name == name) return static_cast<int>(i);
    }
    return -1;
  }

  std::vector<std::string> draft_names() const {
    std::vector<std::string> names;
    for (const BodyDraft& d : drafts_) names.push_back(d.body.name);
    return names;
  }

  int single_base(const Entry& bodies) const {
    int base = -1;
    for (size_t i = 0; i < drafts_.size(); ++i) {
      if (drafts_[i].body.parent >= 0) continue;
      if (base >= 0) {
        fail_at(drafts_[i].key, "bodies",
                "more than one base body: '" + drafts_[base].body.name + "' and '" +
                    drafts_[i].body.name + "' have no parent (exactly one body may have none)");
      }
      base = static_cast<int>(i);
    }
    if (base < 0) {
      fail_at(bodies.key_node, "bodies",
              "no base body: every body has a parent, but exactly one (the machine base) must "
              "have none");
    }
    return base;
  }

  // With one base, a body not reachable from it lies on (or hangs off) a cycle of parent links.
  void check_cycles(int base) const {
    const int n = static_cast<int>(drafts_.size());
    for (int start = 0; start < n; ++start) {
      std::vector<int> seen;
      int b = start;
      while (b >= 0 && b != base && std::find(seen.begin(), seen.end(), b) == seen.end()) {
        seen.push_back(b);
        b = drafts_[b].body.parent;
      }
      if (b < 0 || b == base) continue;
      // b is the first body met twice: the cycle is b -> ... -> b.
      std::string names = drafts_[b].body.name;
      for (int c = drafts_[b].body.parent; c != b; c = drafts_[c].body.parent) {
        names += " -> " + drafts_[c].body.name;
      }
      names += " -> " + drafts_[b].body.name;
      fail(drafts_[b].parent_field,
           "parent links form a cycle: " + names + " (the bodies must form a tree)");
    }
  }

  // Base first, parents before children, otherwise file order.
  std::vector<int> tree_order(int base) const {
    std::vector<int> order{base};
    std::vector<bool> placed(drafts_.size(), false);
    placed[static_cast<size_t>(base)] = true;
    while (order.size() < drafts_.size()) {
      for (size_t i = 0; i < drafts_.size(); ++i) {
        const int parent = drafts_[i].body.parent;
        if (!placed[i] && parent >= 0 && placed[static_cast<size_t>(parent)]) {
          placed[i] = true;
          order.push_back(static_cast<int>(i));
        }
      }
    }
    return order;
  }

  // Moves the drafts into the description in `order`, renumbering parents and errors.
  void apply_order(const std::vector<int>& order) {
    std::vector<int> new_index(drafts_.size());
    for (size_t k = 0; k < order.size(); ++k)
      new_index[static_cast<size_t>(order[k])] = static_cast<int>(k);
    for (int old : order) {
      Body body = drafts_[static_cast<size_t>(old)].body;
      if (body.parent >= 0) body.parent = new_index[static_cast<size_t>(body.parent)];
      const int b = static_cast<int>(d_.bodies.size());
      for (int& e : body.errors) {
        ErrorDef err = errors_[static_cast<size_t>(e)];
        err.body = b;
        e = static_cast<int>(d_.errors.size());
        d_.errors.push_back(std::move(err));
      }
      d_.bodies.push_back(std::move(body));
    }
  }

  // ---- Errors ---------------------------------------------------------------------------------

  void read_body_errors(int b, const Entry* e) {
    const BodyDraft& draft = drafts_[static_cast<size_t>(b)];
    const bool moving = draft.body.joint.type != JointType::Fixed;
    if (!e) {
      if (moving) expand_iso(b, {draft.key, draft.key, draft.path}, true);
      return;
    }
    const Field& f = e->value;
    if (f.node.IsScalar() && f.node.Scalar() == "none") return;
    if (f.node.IsScalar() && f.node.Scalar() == "iso") {
      if (!moving) {
        fail(f, "'iso' needs a moving joint, and body '" + draft.body.name +
                    "' has none (use 'none' or custom errors)");
      }
      expand_iso(b, f, false);
      return;
    }
    if (!f.node.IsMap()) fail(f, "expected 'iso', 'none' or a mapping from error name to error");
    const MapView m = map(f, {}, "error name");
    for (const Entry& err : m.entries) add_error(b, read_error(b, err, f.path));
  }

  void add_error(int b, ErrorDef err) {
    drafts_[static_cast<size_t>(b)].body.errors.push_back(static_cast<int>(errors_.size()));
    errors_.push_back(std::move(err));
  }

  // The six ISO motion errors of body b's joint; `at` is the `errors: iso` value or the body key.
  void expand_iso(int b, const Field& at, bool implicit) {
    const Joint& joint = drafts_[static_cast<size_t>(b)].body.joint;
    const std::string why = implicit ? "a moving body without 'errors' gets the six ISO 230-1 "
                                       "motion errors"
                                     : "errors: iso";
    std::vector<std::string> names;
    try {
      names = iso_motion_errors(joint);
    } catch (const std::invalid_argument& ex) {
      fail(at, why + ", but " + ex.what());
    }
    for (const std::string& name : names) {
      ErrorDef err = iso_error(name, match_iso_name(joint, name).error);
      err.loc = loc(at.where);
      claim_error_names(err, at, {});
      apply_group_default(err, false, at, implicit ? " (implicit errors: iso)" : " (errors: iso)");
      err.to_base = find_unit(kErrorUnits, err.unit)->to_base;
      add_error(b, std::move(err));
    }
  }

  static ErrorDef iso_error(const std::string& name, const IsoError& iso) {
    ErrorDef err;
    err.name = name;
    err.iso = name;
    err.effect = iso.effect;
    err.direction = iso.direction;
    err.group = iso.group;
    err.placement = iso.placement;
    err.dependence = iso.dependence;
    err.unit = iso.unit;
    return err;
  }

  ErrorDef read_error(int b, const Entry& e, const std::string& errors_path) {
    const BodyDraft& draft = drafts_[static_cast<size_t>(b)];
    const Field key{e.key_node, e.key_node, errors_path};
    const std::string name = key_identifier(e, errors_path, "error name");
    const MapView m = map(e.value, kErrorKeys);
    const IsoMatch iso = match_iso_name(draft.body.joint, name);
    const bool fits = iso.status == IsoMatch::Status::Fits;
    ErrorDef err = fits ? iso_error(name, iso.error) : ErrorDef{};
    err.name = name;
    err.loc = loc(e.key_node);
    if (!fits) require_custom_keys(m, iso, draft.body.name, name, key);
    read_error_effect(m, err, fits);
    claim_error_names(err, key, read_aliases(m, err));
    if (const Entry* t = m.find("description")) err.description = text(t->value);
    const Entry* unit_entry = m.find("unit");
    if (unit_entry) {
      err.unit = unit(unit_entry->value, kErrorUnits)->name;
      check_dimension(unit_entry->value, err, err.unit);
    } else {
      err.unit = err.effect == ErrorEffect::Rotation ? "urad" : "um";
    }
    if (const std::optional<Distribution> dist = read_distribution(m)) {
      err.distribution = *dist;
    } else {
      apply_group_default(err, unit_entry != nullptr, key, "");
    }
    err.to_base = find_unit(kErrorUnits, err.unit)->to_base;
    return err;
  }

  // A name the ISO table does not cover must say what it does.
  void require_custom_keys(const MapView& m, const IsoMatch& iso, const std::string& body,
                           const std::string& name, const Field& key) const {
    std::vector<std::string> missing;
    for (const char* k : {"effect", "direction", "group"}) {
      if (!m.find(k)) missing.push_back(k);
    }
    if (missing.empty()) return;
    if (iso.status == IsoMatch::Status::Mismatch) {
      fail(key, "'" + name + "' is not an ISO 230-1 error of body '" + body + "': " + iso.reason +
                    " (to define a custom error give effect, direction and group)");
    }
    fail(key, "'" + name + "' is not an ISO 230-1 name, so it is a custom error and needs " +
                  "effect, direction and group (missing: " + join(missing) + ")");
  }

  // effect, direction, group, placement, dependence: given keys override the ISO table.
  void read_error_effect(const MapView& m, ErrorDef& err, bool iso) const {
    if (const Entry* e = m.find("effect")) {
      err.effect = choice<ErrorEffect>(e->value, {{"translation", ErrorEffect::Translation},
                                                  {"rotation", ErrorEffect::Rotation}});
    }
    if (const Entry* e = m.find("direction")) err.direction = direction(e->value);
    if (const Entry* e = m.find("group")) err.group = known_group(e->value);
    if (const Entry* e = m.find("placement")) {
      err.placement = choice<ErrorPlacement>(e->value, {{"after", ErrorPlacement::After},
                                                        {"before", ErrorPlacement::Before},
                                                        {"axis", ErrorPlacement::Axis}});
    } else if (!iso) {
      err.placement = ErrorPlacement::After;
    }
    if (const Entry* e = m.find("basis")) {
      err.basis = basis_text(e->value);
      err.basis_loc = loc(e->value.where);
    }
    if (const Entry* e = m.find("dependence")) {
      err.dependence =
          choice<Dependence>(e->value, {{"PDGE", Dependence::PDGE}, {"PIGE", Dependence::PIGE}});
    } else if (!iso) {
      err.dependence = err.placement == ErrorPlacement::After ? Dependence::PDGE : Dependence::PIGE;
    }
  }

  // Reads `aliases` into err; returns where each alias is written, for duplicate checks.
  std::vector<Field> read_aliases(const MapView& m, ErrorDef& err) const {
    std::vector<Field> fields;
    const Entry* a = m.find("aliases");
    if (!a) return fields;
    for (const Field& item : items(a->value, 0, SIZE_MAX, "a list of aliases")) {
      Alias alias;
      Field name_field = item;
      if (item.node.IsMap()) {
        const MapView am = map(item, kAliasKeys);
        name_field = required(am, "name").value;
        if (const Entry* s = am.find("sign")) alias.sign = read_sign(s->value);
      }
      alias.name = text(name_field);
      const bool blank = std::any_of(alias.name.begin(), alias.name.end(), [](char c) {
        return std::isspace(static_cast<unsigned char>(c));
      });
      if (alias.name.empty() || blank) {
        fail(name_field, "an alias must be non-empty text without spaces");
      }
      err.aliases.push_back(alias);
      fields.push_back(name_field);
    }
    return fields;
  }

  int read_sign(const Field& f) const {
    const std::string sign = text(f);
    if (sign == "-1") return -1;
    if (sign != "1" && sign != "+1") fail(f, "sign must be 1 or -1, got '" + sign + "'");
    return 1;
  }

  void claim_error_names(const ErrorDef& err, const Field& key,
                         const std::vector<Field>& alias_fields) {
    claim(error_names_, err.name, {"error name", err.name, loc(key.where).line}, key);
    claim_symbol(err.name, "error name", key);
    for (size_t i = 0; i < err.aliases.size(); ++i) {
      const Field& at = alias_fields[i];
      claim(error_names_, err.aliases[i].name, {"alias", err.name, loc(at.where).line}, at);
    }
  }

  // An error's unit must measure what the error does.
  void check_dimension(const Field& at, const ErrorDef& err, const std::string& unit_name) const {
    const bool angle = find_unit(kErrorUnits, unit_name)->angle;
    const bool rotation = err.effect == ErrorEffect::Rotation;
    if (angle != rotation) {
      fail(at, "unit '" + unit_name + "' is " + (angle ? "an angle" : "a length") + " but error '" +
                   err.name + "' is a " + (rotation ? "rotation" : "translation"));
    }
  }

  // The distribution (and, unless given, the unit) from error_defaults[group].
  void apply_group_default(ErrorDef& err, bool unit_given, const Field& at,
                           const std::string& context) const {
    const auto it = defaults_.find(err.group);
    if (it == defaults_.end()) {
      fail(at, "error '" + err.name + "'" + context +
                   " has no distribution (sigma, normal, uniform or truncnormal) and "
                   "error_defaults has none for its group '" +
                   err.group + "'");
    }
    const GroupDefault& def = it->second;
    if (!unit_given && !def.unit.empty()) err.unit = def.unit;
    double scale = 1;
    if (!def.unit.empty()) {
      check_dimension(default_units_.at(err.group), err, def.unit);
      scale = find_unit(kErrorUnits, def.unit)->to_base / find_unit(kErrorUnits, err.unit)->to_base;
    }
    err.distribution = def.distribution;
    err.distribution.a *= scale;
    err.distribution.b *= scale;
    err.distribution.lo *= scale;
    err.distribution.hi *= scale;
  }

  // ---- Tool, workpiece, algebra ---------------------------------------------------------------

  PointSpec read_point_spec(const Field& f) const {
    const MapView m = map(f, kPointKeys);
    PointSpec p;
    p.loc = loc(f.where);
    const Field& body = required(m, "body").value;
    p.body = d_.body_index(text(body));
    if (p.body < 0) {
      fail(body, "unknown body '" + text(body) + "' (bodies: " + join(draft_names()) + ")");
    }
    if (const Entry* pt = m.find("point")) p.point = point(pt->value);
    return p;
  }

  void read_algebra(const Field& f) {
    const MapView m = map(f, kAlgebraKeys);
    if (const Entry* o = m.find("order")) d_.algebra.order = read_order(o->value);
    if (const Entry* r = m.find("relations")) {
      for (const Field& item : items(r->value, 0, SIZE_MAX, "a list of relations")) {
        d_.algebra.relations.push_back(read_relation(item));
      }
    }
  }

  int read_order(const Field& f) const {
    const std::string s = text(f);
    int order = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), order);
    if (ec != std::errc() || end != s.data() + s.size()) {
      fail(f, "order must be a whole number >= 1, got '" + s + "'");
    }
    if (order < 1) fail(f, "order must be >= 1, got " + s);
    return order;
  }

  Relation read_relation(const Field& f) const {
    static const std::vector<std::string> kinds = {"squares", "within", "between", "pair",
                                                   "monomial"};
    const MapView m = map(f, kinds);
    if (m.entries.size() != 1) fail(f, "a relation is one of " + join(kinds) + " with its names");
    const Entry& e = m.entries.front();
    Relation r;
    r.loc = loc(f.where);
    if (e.key == "squares") {
      r.kind = Relation::Kind::Squares;
      if (e.value.node.IsScalar() && e.value.node.Scalar() == "all") return r;
      r.names = error_names(items(e.value, 1, SIZE_MAX, "'all' or a list of error names"));
    } else if (e.key == "within") {
      r.kind = Relation::Kind::Within;
      r.names = group_names(items(e.value, 1, SIZE_MAX, "a list of group names"));
    } else if (e.key == "between") {
      r.kind = Relation::Kind::Between;
      r.names = group_names(items(e.value, 2, 2, "[group, group]"));
    } else if (e.key == "pair") {
      r.kind = Relation::Kind::Pair;
      r.names = error_names(items(e.value, 2, 2, "[error, error]"));
    } else {
      r.kind = Relation::Kind::Monomial;
      r.names = error_names(items(e.value, 1, SIZE_MAX, "a list of error names"));
    }
    return r;
  }

  // Error names or aliases, resolved to error names.
  std::vector<std::string> error_names(const std::vector<Field>& fields) const {
    std::vector<std::string> names;
    for (const Field& f : fields) {
      const int i = d_.error_index(text(f));
      if (i < 0) fail(f, "relation names no error '" + text(f) + "'");
      names.push_back(d_.errors[static_cast<size_t>(i)].name);
    }
    return names;
  }

  std::vector<std::string> group_names(const std::vector<Field>& fields) const {
    std::vector<std::string> names;
    for (const Field& f : fields) {
      if (!has_group(text(f))) {
        fail(f, "relation names no group '" + text(f) + "' (known: " + join(d_.groups) + ")");
      }
      names.push_back(text(f));
    }
    return names;
  }

  std::string file_;
  Description d_;
  std::map<std::string, double> parameter_defaults_;
  std::map<std::string, GroupDefault> defaults_;
  std::map<std::string, Field> default_units_;  // where each group default's unit is written
  std::map<std::string, Claim> error_names_;    // error names and aliases
  std::map<std::string, Claim> symbols_;        // parameters, coordinates, error names
  std::vector<BodyDraft> drafts_;
  std::vector<ErrorDef> errors_;              // in file order; moved into d_ in tree order
  std::vector<std::string> parameter_names_;  // in file order, for messages
};

}  // namespace

YAML::Node parse_yaml(const std::string& text, const std::string& filename) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& ex) {
    throw InputError({filename, ex.mark.line + 1, ex.mark.column + 1},
                     "YAML syntax error: " + ex.msg);
  }
}

Description load_machine_text(const std::string& yaml, const std::string& filename) {
  const YAML::Node root = parse_yaml(yaml, filename);
  Description desc = Loader(filename).load(root);
  desc.source_hash = fnv1a64(yaml);
  return desc;
}

Description load_machine_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError({path, 0, 0}, "is a directory, not a machine file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path, 0, 0}, "cannot read the machine file");
  std::ostringstream text;
  text << in.rdbuf();
  return load_machine_text(text.str(), path);
}

Distribution read_distribution_keys(const YAML::Node& mapping, const std::string& file,
                                    const std::string& path) {
  return Loader(file).distribution_keys(mapping, path);
}

std::string shipped_machines_dir() {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (const char* env = std::getenv("WEILGEN_MACHINES_DIR"); env && *env) return env;
  if (fs::is_directory(WEILGEN_MACHINES_DIR, ec)) return WEILGEN_MACHINES_DIR;
  // An installed weilgen: <prefix>/bin/weilgen and <prefix>/share/weilgen/machines.
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "weilgen" / "machines";
    if (fs::is_directory(installed, ec)) return installed.string();
  }
  return WEILGEN_MACHINES_DIR;
}

std::string resolve_machine(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(name_or_path, ec)) return name_or_path;
  const std::string dir = shipped_machines_dir();
  const fs::path shipped = fs::path(dir) / (name_or_path + ".yaml");
  if (is_identifier(name_or_path) && fs::is_regular_file(shipped, ec)) return shipped.string();
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  throw InputError({name_or_path, 0, 0},
                   "no such machine file, and no shipped machine of that name (shipped: " +
                       (names.empty() ? std::string("none") : join(names)) + ")");
}

}  // namespace weilgen
