// What a machine is: bodies, joints, static offsets, error components, the algebra and the
// outputs. Filled by the YAML loader (yaml_loader.hpp), read by the generator (GiNaC) and by the
// exact numeric chain (numeric_chain.hpp). Plain data: no GiNaC, no Eigen.
//
// Units inside a Description: lengths in mm, angles in rad (the "base" units). Joint coordinates
// of revolute joints are *given* in `Joint::unit` (deg by default) at the API and converted with
// `Joint::to_base`. Error values are given to generated code in base units; `ErrorDef::to_base`
// converts from the error's declared unit (um, urad, ...) to base.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "weilgen/base/error.hpp"
#include "weilgen/base/expr.hpp"

namespace weilgen {

using Vec3 = std::array<double, 3>;

enum class JointType { Fixed, Prismatic, Revolute };

// A static rotation about a unit axis by an angle in degrees (number or parameter expression).
struct StaticRotation {
  Vec3 axis{0, 0, 1};
  Expr angle_deg = Expr::num(0);
};

// Static placement of a body in its parent: translation (mm), then rotations in listed order.
struct Offset {
  std::array<Expr, 3> translation{Expr::num(0), Expr::num(0), Expr::num(0)};
  std::vector<StaticRotation> rotations;
  bool is_identity() const;
};

// A moving joint, J(q) in its parent's frame. Given either in axis form (type, axis, optional
// `through`) or as a twist ξ = (ω, v) with J(q) = exp(ξ^ q) (Jiang et al. 2021's POE form): ω = 0
// is a prismatic joint along v, |ω| = 1 with ω·v = 0 a revolute joint about ω through ω × v. Both
// forms fill the same fields; `twist` keeps the text as written for reports.
struct Joint {
  JointType type = JointType::Fixed;
  Vec3 axis{0, 0, 0};  // unit direction (prismatic) or rotation axis (revolute), parent frame
  // Revolute: a point of the rotation axis line, parent frame, mm (origin unless `through`/twist).
  std::array<Expr, 3> through{Expr::num(0), Expr::num(0), Expr::num(0)};
  std::string twist;  // "[0, 0, 0, 1, 0, 0]" when given as a twist, else empty
  // A linked joint (Y23.2 = -Y23.1): its value, in `unit`, as an expression of other coordinates
  // and parameters. Linked joints are not inputs of the model (Description::axes() skips them).
  std::optional<Expr> link;
  std::string coordinate;   // "X", "C", any identifier
  std::string unit;         // mm | um | m for prismatic; deg | rad for revolute
  double to_base = 1.0;     // coordinate value in `unit` * to_base = mm or rad
  double min = 0, max = 0;  // travel range, in `unit`
  SourceLoc loc;
};

enum class ErrorEffect { Translation, Rotation };

// Where an error's elementary transform sits in its body's transform
//   T(body) = Offset · E_before · (E_axis · J(q) · E_axis⁻¹) · E_after
// After: error motion of the carriage (ISO 230-1 E_XX ... E_CX), carried with the body.
// Before: a constant offset of the body's frame before the motion.
// Axis: a displacement/tilt of the joint's axis line (squareness E_C0Y, location E_X0C): it moves
//       or tilts the line of motion, not the body's orientation at q = 0.
enum class ErrorPlacement { After, Before, Axis };

enum class Dependence { PIGE, PDGE };

struct Distribution {
  enum class Kind { None, Normal, Uniform, TruncatedNormal };
  Kind kind = Kind::None;
  // Values in the error's declared unit. Normal: a=mean, b=sigma. Uniform: a=lo, b=hi.
  // TruncatedNormal: a=mean, b=sigma, lo, hi.
  double a = 0, b = 0, lo = 0, hi = 0;
  std::string str() const;  // "normal(0, 0.008333)" etc.
};

// A paper's notation for an error: value(alias) = sign * value(error).
struct Alias {
  std::string name;
  int sign = 1;
};

struct ErrorDef {
  std::string name;  // ISO 230-1 name (E_XX, E_C0Y) or a custom identifier
  std::string iso;   // ISO 230-1 name when the error is one, else empty
  std::vector<Alias> aliases;
  std::string group;  // positioning, straightness, angular, ... (see known_groups)
  std::string unit;   // unit of distribution values: mm, um, nm, rad, mrad, urad, arcsec, deg
  double to_base = 1.0;
  Dependence dependence = Dependence::PDGE;
  Distribution distribution;
  ErrorEffect effect = ErrorEffect::Translation;
  Vec3 direction{1, 0, 0};  // unit vector in the body frame (before the motion for Before/Axis)
  ErrorPlacement placement = ErrorPlacement::After;
  int body = -1;  // index into Description::bodies
  std::string description;
  // Identification basis of a PDGE ("poly:3", "fourier:2:20"; machine/pdge_basis.hpp); empty =
  // the machine's pdge_basis, else the identify default.
  std::string basis;
  SourceLoc basis_loc;
  SourceLoc loc;
  // The base unit of its values inside the libraries: "rad" for a rotation, else "mm".
  const char* base_unit() const { return effect == ErrorEffect::Rotation ? "rad" : "mm"; }
};

struct Body {
  std::string name;
  int parent = -1;  // index into Description::bodies; -1 for the base
  Offset offset;
  Joint joint;
  std::vector<int> errors;  // indices into Description::errors, in composition order
  SourceLoc loc;
};

struct Parameter {
  std::string name;
  double value = 0;  // default value, in `unit`
  std::string unit;  // mm or deg (informational; lengths are mm, angles deg)
  std::string description;
};

// Monomial relations of the algebra: R[e_1..e_k] / I, I = <all monomials of degree r+1> + <gens>.
struct Relation {
  enum class Kind { Squares, Within, Between, Pair, Monomial };
  Kind kind = Kind::Squares;
  // Squares: errors whose squares vanish (empty = all errors);
  // Within: group names (products of two errors of one group vanish);
  // Between: two group names; Pair: two error names; Monomial: error names (with repeats).
  std::vector<std::string> names;
  SourceLoc loc;
};

struct Algebra {
  int order = 1;  // r >= 1; r = 1 is dual numbers
  std::vector<Relation> relations;
};

struct PointSpec {
  int body = -1;
  std::array<Expr, 3> point{Expr::num(0), Expr::num(0), Expr::num(0)};  // mm, body frame
  SourceLoc loc;
};

// A point on a chain whose deviation P(e) − P(0) (mm, base frame) derived quantities use as
// `name.x`, `name.y`, `name.z` (Jiang et al. 2021's E_0N of each jaw tip).
struct ChainPoint {
  std::string name;
  PointSpec at;
};

// A direction fixed in a body (unit vector, body frame) and its nominal value in the base frame at
// the current pose, R(q, e = 0) · direction: derived quantities use it as `name.x`, `name.y`,
// `name.z` (dimensionless) to project deviations on a moving direction, such as a chuck's
// clamping direction after the chuck has turned.
struct ChainDirection {
  std::string name;
  int body = -1;
  Vec3 direction{1, 0, 0};
  SourceLoc loc;
};

// A named scalar of the algebra (mm, rad or dimensionless), in file order; its expression may use
// parameters, coordinates (independent or linked), point components `P.x` and earlier derived
// quantities. Divisors must be nominal (no error dependence) and non-zero over the travel range.
struct Derived {
  std::string name;
  Expr value;
  bool nominal = false;  // depends on no error (may be a divisor)
  std::string description;
  SourceLoc loc;
};

// One factor of the output transform: a translation (mm) or exp(ξ^ · amount) for a twist
// ξ = (ω, v) (amount in rad when ω ≠ 0, else mm). Components are expressions like Derived.
struct TransformStep {
  enum class Kind { Translate, Twist };
  Kind kind = Kind::Translate;
  std::array<Expr, 3> translation{Expr::num(0), Expr::num(0), Expr::num(0)};
  Vec3 omega{0, 0, 0};
  std::array<Expr, 3> v{Expr::num(0), Expr::num(0), Expr::num(0)};
  Expr amount = Expr::num(0);
  SourceLoc loc;
};

// An output built from derived quantities instead of the tool/workpiece branches:
// P = Π steps · Trans(point); dx..dc are the deviation of P as for W⁻¹·T.
struct OutputTransform {
  std::vector<TransformStep> steps;
  std::array<Expr, 3> point{Expr::num(0), Expr::num(0), Expr::num(0)};
  std::string description;  // what the output point is (report, `weilgen show`)
  SourceLoc loc;
};

// How a LinuxCNC configuration sees the model's axes (machines/README.md, "linuxcnc"): what
// the file says; machine/linuxcnc.hpp derives the defaults (signs, letters, joint numbers).
struct LinuxcncAxisSpec {
  std::string coordinate;        // the model axis (an independent coordinate)
  std::optional<int> sign;       // +1 or -1: model = offset + sign * scale * LinuxCNC joint
  std::optional<double> offset;  // the model coordinate at LinuxCNC's joint zero, axis unit
  std::string letter;            // LinuxCNC axis letter (X Y Z A B C U V W); empty: default
  std::optional<int> joint;      // LinuxCNC joint number; default: trivkins order
  SourceLoc loc;
};

struct LinuxcncSpec {
  std::string linear_units;  // LinuxCNC's [TRAJ]LINEAR_UNITS: "mm" or "inch"; empty: mm
  std::vector<LinuxcncAxisSpec> axes;
  SourceLoc loc;  // the section (0 when the file has none)
};

struct Description {
  std::string name;               // identifier, used for file and namespace names
  std::string title;              // human title
  std::string source_file;        // path the description was read from
  std::uint64_t source_hash = 0;  // FNV-1a of the machine file's text (model_key.hpp)
  std::string notes;              // free text (corrections to the source paper, conventions)
  Algebra algebra;
  std::vector<Parameter> parameters;
  std::vector<std::string> groups;  // builtin_groups() plus the file's `groups:`
  std::vector<Body> bodies;         // bodies[0] is the base; parents precede children
  std::vector<ErrorDef> errors;
  PointSpec tool;       // tool point (cutting point) on the tool branch (unset with `output`)
  PointSpec workpiece;  // workpiece coordinate system origin on the workpiece branch
  std::vector<ChainPoint> points;          // chain points used by derived quantities
  std::vector<ChainDirection> directions;  // nominal body directions used by derived quantities
  std::vector<Derived> derived;            // in evaluation (file) order
  std::optional<OutputTransform> output;   // replaces W⁻¹·T when present
  std::string pdge_basis;                  // default identification basis of PDGEs ("poly:3")
  SourceLoc pdge_basis_loc;                //   of linear axes (prismatic joints)
  std::string pdge_basis_revolute;         // ... of rotary axes (revolute joints)
  SourceLoc pdge_basis_revolute_loc;
  LinuxcncSpec linuxcnc;  // the `linuxcnc:` section (empty when absent)

  // Index lookups; -1 when absent.
  int body_index(const std::string& name) const;
  int error_index(const std::string& name) const;  // by name or alias
  // The model's input axes in tree order: bodies with a prismatic or revolute joint that is not
  // linked to other coordinates.
  std::vector<int> axes() const;
  // The joint of input axis `axis` (an index into axes()).
  const Joint& axis_joint(std::size_t axis) const;
  // Bodies with a linked joint, in tree order.
  std::vector<int> linked_axes() const;
  // Body whose joint coordinate is `coordinate` (independent or linked); -1 when none.
  int coordinate_body(const std::string& coordinate) const;
  // Path from the base to body b (base first, b last).
  std::vector<int> chain_to(int b) const;
  std::map<std::string, double> parameter_defaults() const;
};

// Groups an error may belong to; machine files may declare more under `groups:`.
const std::vector<std::string>& builtin_groups();

// The errors' names, in Description::errors order (for messages).
std::vector<std::string> error_names(const Description& desc);
// Groups that have at least one error, in Description::groups order.
std::vector<std::string> used_groups(const Description& desc);

}  // namespace weilgen
