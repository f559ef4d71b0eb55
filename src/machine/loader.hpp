// Internals of the machine-file reader (machines/README.md), shared by its files:
//   loader_yaml.cpp      located YAML reading: positions, mappings, scalars, numbers, expressions
//   loader_schema.cpp    the file's top level: version, parameters, groups, units, distributions
//   loader_topology.cpp  bodies, offsets, joints (axis form and twists), links, the body tree
//   loader_errors.cpp    error components: ISO names, custom errors, aliases, groups
//   loader_defaults.cpp  error_defaults (per group, per kind) and pdge_basis (per joint type)
//   loader_chains.cpp    chain points and directions, derived quantities, the output
//                        transform, tool, workpiece and algebra
//   loader_linuxcnc.cpp  the linuxcnc section (signs, offsets, letters, joints, units)
//   yaml_loader.cpp      the public API (weilgen/machine/yaml_loader.hpp) and Loader::load
#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/machine/description.hpp"
#include "weilgen/machine/iso_names.hpp"

namespace weilgen::machine_detail {

// The units a field accepts, by their table spelling (weilgen/base/units.hpp holds the factors;
// µm and µrad are accepted for um and urad).
const std::vector<std::string> kErrorUnits = {"mm",   "um",   "nm",     "rad",
                                              "mrad", "urad", "arcsec", "deg"};
const std::vector<std::string> kPrismaticUnits = {"mm", "um", "m"};
const std::vector<std::string> kRevoluteUnits = {"deg", "rad"};
const std::vector<std::string> kParameterUnits = {"mm", "deg"};

// A unit of one of those lists: its table name, factor to mm or rad, and dimension.
struct Unit {
  std::string name;
  double to_base = 1;
  bool angle = false;
};

inline Unit table_unit(const std::string& name) {
  const UnitFactor f = parse_unit(name);
  return {name, f.to_base, f.angle};
}

const std::vector<std::string> kTopKeys = {
    "weilgen", "name",           "title",      "notes",      "algebra",   "parameters",
    "groups",  "error_defaults", "bodies",     "tool",       "workpiece", "points",
    "derived", "output",         "pdge_basis", "directions", "linuxcnc"};
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
const std::vector<std::string> kDefaultKeys = {"sigma", "normal",      "uniform", "truncnormal",
                                               "unit",  "translation", "rotation"};
const std::vector<std::string> kKindDefaultKeys = {"sigma", "normal", "uniform", "truncnormal",
                                                   "unit"};
const std::vector<std::string> kParameterKeys = {"value", "unit", "description"};
const std::vector<std::string> kPointKeys = {"body", "point"};
const std::vector<std::string> kDirectionKeys = {"body", "direction"};
const std::vector<std::string> kAlgebraKeys = {"order", "relations"};
const std::vector<std::string> kAliasKeys = {"name", "sign"};
const std::vector<std::string> kLinuxcncKeys = {"units", "axes"};
const std::vector<std::string> kLinuxcncAxisKeys = {"sign", "offset", "letter", "joint"};

inline bool is_identifier(const std::string& s) {
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

inline std::string sub_path(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

// Default distribution of an error group (`error_defaults`), for all its errors or for one kind
// (translations or rotations: a group such as `location` holds both).
struct GroupDefault {
  Distribution distribution;
  std::string unit;  // empty: values are in the error's unit
  Field unit_at;     // where the unit is written (messages)
};

struct GroupDefaults {
  std::optional<GroupDefault> any, translation, rotation;
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

  Description load(const YAML::Node& root);

  // A PDGE basis spelling (poly:3, fourier:2:20); checked here so a typo names its line.
  std::string basis_text(const Field& f) const;

  // read_distribution_keys(): the distribution keys of any mapping, other keys ignored.
  Distribution distribution_keys(const YAML::Node& node, const std::string& path) const;

 private:
  // ---- Reporting and generic readers -------------------------------------------------------

  SourceLoc loc(const YAML::Node& n) const;

  [[noreturn]] void fail(const Field& f, const std::string& message) const;

  [[noreturn]] void fail_at(const YAML::Node& at, const std::string& path,
                            const std::string& message) const;

  // A mapping (null reads as empty) whose keys are unique, scalar and among `allowed` (when given).
  MapView map(const Field& f, const std::vector<std::string>& allowed,
              const char* key_kind = "key") const;

  const Entry& required(const MapView& m, const std::string& key) const;

  std::string text(const Field& f) const;

  std::string identifier(const Field& f, const std::string& what) const;

  std::string key_identifier(const Entry& e, const std::string& parent_path,
                             const std::string& what) const;

  std::vector<Field> items(const Field& f, size_t min, size_t max, const std::string& form) const;

  Expr parsed(const Field& f) const;

  double finite(const Field& f, double v) const;

  // A number, possibly written as an expression without parameters ("0.05/6").
  double number(const Field& f) const;

  double positive(const Field& f, const std::string& what) const;

  // An expression over the declared parameters (offsets, points, static angles).
  Expr expression(const Field& f) const;

  std::array<Expr, 3> point(const Field& f) const;

  // x, -y, ... or [ax, ay, az], normalised.
  Vec3 direction(const Field& f) const;

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
             const Field& at) const;

  // Parameters, coordinates and error names are all symbols of the generated model.
  void claim_symbol(const std::string& name, const std::string& kind, const Field& at);

  // ---- Top-level sections --------------------------------------------------------------------

  void read_version(const Entry& e);

  void read_parameters(const Field& f);

  std::optional<Unit> unit(const Field& f, const std::vector<std::string>& allowed) const;

  void read_groups(const Field& f);

  bool has_group(const std::string& g) const;

  std::string known_group(const Field& f) const;

  // error_defaults (loader_defaults.cpp): per group a distribution, or per kind
  // (translation, rotation) one each.
  void read_error_defaults(const Field& f);

  // One default's distribution and unit; `kind` (translation or rotation) checks the unit's
  // dimension, empty accepts any.
  std::optional<GroupDefault> read_group_default(const MapView& m, const std::string& kind) const;

  // pdge_basis: one basis for every PDGE, or {prismatic: ..., revolute: ...} (loader_defaults.cpp).
  void read_pdge_basis(const Field& f);

  // sigma | normal | uniform | truncnormal, at most one; values in the caller's unit.
  std::optional<Distribution> read_distribution(const MapView& m) const;

  void check_interval(const Field& f, double lo, double hi) const;

  // ---- Bodies ---------------------------------------------------------------------------------

  void read_bodies(const Entry& bodies);

  void read_body(int b, const Entry& e);

  Offset read_offset(const Field& f) const;

  Joint read_joint(const Entry& e);

  // The six fields of a twist [ωx, ωy, ωz, vx, vy, vz] and its ω: numbers, a unit vector or zero.
  std::vector<Field> twist_fields(const Field& f, Vec3& w) const;

  // ξ = [ωx, ωy, ωz, vx, vy, vz] (Jiang et al. 2021's twists): ω numbers, v expressions over
  // parameters.
  void read_twist(const Field& f, std::optional<JointType> declared, Joint& j) const;

  // ---- Points, derived quantities, output transform ---------------------------------------

  void read_points(const Field& f);

  // Nominal body directions (`directions:`), after the bodies.
  void read_directions(const Field& f);

  void read_derived(const Field& f);

  OutputTransform read_output(const Field& f) const;

  // Names in output and derived expressions are resolved by check_derived() (machine/derived.hpp).
  std::array<Expr, 3> point_formula(const Field& f) const;

  // Parent names to indices (file order).
  void link_parents();

  int draft_index(const std::string& name) const;

  std::vector<std::string> draft_names() const;

  int single_base(const Entry& bodies) const;

  // With one base, a body not reachable from it lies on (or hangs off) a cycle of parent links.
  void check_cycles(int base) const;

  // Base first, parents before children, otherwise file order.
  std::vector<int> tree_order(int base) const;

  // Moves the drafts into the description in `order`, renumbering parents and errors.
  void apply_order(const std::vector<int>& order);

  // ---- Errors ---------------------------------------------------------------------------------

  void read_body_errors(int b, const Entry* e);

  void add_error(int b, ErrorDef err);

  // The six ISO motion errors of body b's joint; `at` is the `errors: iso` value or the body key.
  void expand_iso(int b, const Field& at, bool implicit);

  static ErrorDef iso_error(const std::string& name, const IsoError& iso);

  ErrorDef read_error(int b, const Entry& e, const std::string& errors_path);

  // A name the ISO table does not cover must say what it does.
  void require_custom_keys(const MapView& m, const IsoMatch& iso, const std::string& body,
                           const std::string& name, const Field& key) const;

  // effect, direction, group, placement, dependence: given keys override the ISO table.
  void read_error_effect(const MapView& m, ErrorDef& err, bool iso) const;

  // Reads `aliases` into err; returns where each alias is written, for duplicate checks.
  std::vector<Field> read_aliases(const MapView& m, ErrorDef& err) const;

  int read_sign(const Field& f) const;

  void claim_error_names(const ErrorDef& err, const Field& key,
                         const std::vector<Field>& alias_fields);

  // An error's unit must measure what the error does.
  void check_dimension(const Field& at, const ErrorDef& err, const std::string& unit_name) const;

  // The distribution (and, unless given, the unit) from error_defaults[group].
  void apply_group_default(ErrorDef& err, bool unit_given, const Field& at,
                           const std::string& context) const;

  // ---- LinuxCNC (loader_linuxcnc.cpp) --------------------------------------------------------

  // The `linuxcnc:` section, after the bodies: units and per-axis sign, offset, letter, joint.
  void read_linuxcnc(const Field& f);

  // ---- Tool, workpiece, algebra ---------------------------------------------------------------

  PointSpec read_point_spec(const Field& f) const;

  // A body named in `body` (points, directions), as its index.
  int body_ref(const Field& body) const;

  void read_algebra(const Field& f);

  int read_order(const Field& f) const;

  Relation read_relation(const Field& f) const;

  // Error names or aliases, resolved to error names.
  std::vector<std::string> error_names(const std::vector<Field>& fields) const;

  std::vector<std::string> group_names(const std::vector<Field>& fields) const;

  std::string file_;
  Description d_;
  std::map<std::string, double> parameter_defaults_;
  std::map<std::string, GroupDefaults> defaults_;
  std::map<std::string, Claim> error_names_;  // error names and aliases
  std::map<std::string, Claim> symbols_;      // parameters, coordinates, error names
  std::vector<BodyDraft> drafts_;
  std::vector<ErrorDef> errors_;              // in file order; moved into d_ in tree order
  std::vector<std::string> parameter_names_;  // in file order, for messages
};

}  // namespace weilgen::machine_detail
