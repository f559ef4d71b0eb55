// error_defaults: a default distribution per error group, for all its errors or per kind.
//
//   error_defaults:
//     positioning: {sigma: 5, unit: um}
//     location:                              # E_X0C is a length, E_C0C an angle
//       translation: {sigma: 5, unit: um}
//       rotation: {uniform: [-10, 10], unit: urad}
//
// A kind's entry overrides the group's own distribution for the errors of that kind. Units come
// from the one unit table (weilgen/base/units.hpp) through Loader::unit.
#include <optional>
#include <string>

#include "loader.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen::machine_detail {

void Loader::read_error_defaults(const Field& f) {
  const MapView m = map(f, {}, "group");
  for (const Entry& e : m.entries) {
    const std::string group = known_group({e.key_node, e.key_node, f.path});
    const MapView dm = map(e.value, kDefaultKeys);
    GroupDefaults defs;
    defs.any = read_group_default(dm, "");
    for (const char* kind : {"translation", "rotation"}) {
      const Entry* k = dm.find(kind);
      if (!k) continue;
      const std::optional<GroupDefault> def =
          read_group_default(map(k->value, kKindDefaultKeys), kind);
      if (!def) fail(k->value, "give a distribution (" + join(kDistributionKeys) + ")");
      (std::string(kind) == "translation" ? defs.translation : defs.rotation) = def;
    }
    if (!defs.any && !defs.translation && !defs.rotation) {
      fail(dm.self, "give a distribution (" + join(kDistributionKeys) +
                        ") or one per kind ({translation: {...}, rotation: {...}})");
    }
    if (defs.any && defs.translation && defs.rotation) {
      fail(dm.self,
           "the group's own distribution applies to no error: both kinds "
           "(translation, rotation) have their own");
    }
    if (!defs.any && dm.find("unit")) {
      fail(dm.find("unit")->value,
           "'unit' goes with a distribution; per kind, write it inside translation/rotation");
    }
    defaults_[group] = defs;
  }
}

std::optional<GroupDefault> Loader::read_group_default(const MapView& m,
                                                       const std::string& kind) const {
  const std::optional<Distribution> dist = read_distribution(m);
  if (!dist) return std::nullopt;
  GroupDefault def;
  def.distribution = *dist;
  if (const Entry* u = m.find("unit")) {
    const Unit unit_read = *unit(u->value, kErrorUnits);
    def.unit = unit_read.name;
    def.unit_at = u->value;
    if (!kind.empty() && unit_read.angle != (kind == "rotation")) {
      fail(u->value, "unit '" + text(u->value) + "' is " +
                         (unit_read.angle ? "an angle" : "a length") + " but a " + kind +
                         " default needs " + (unit_read.angle ? "a length" : "an angle"));
    }
  }
  return def;
}

void Loader::read_pdge_basis(const Field& f) {
  if (!f.node.IsMap()) {
    d_.pdge_basis = d_.pdge_basis_revolute = basis_text(f);
    d_.pdge_basis_loc = d_.pdge_basis_revolute_loc = loc(f.where);
    return;
  }
  const MapView m = map(f, {"prismatic", "revolute"}, "joint type");
  if (const Entry* e = m.find("prismatic")) {
    d_.pdge_basis = basis_text(e->value);
    d_.pdge_basis_loc = loc(e->value.where);
  }
  if (const Entry* e = m.find("revolute")) {
    d_.pdge_basis_revolute = basis_text(e->value);
    d_.pdge_basis_revolute_loc = loc(e->value.where);
  }
}

void Loader::apply_group_default(ErrorDef& err, bool unit_given, const Field& at,
                                 const std::string& context) const {
  const bool rotation = err.effect == ErrorEffect::Rotation;
  const auto it = defaults_.find(err.group);
  const GroupDefault* def = nullptr;
  if (it != defaults_.end()) {
    const std::optional<GroupDefault>& kind =
        rotation ? it->second.rotation : it->second.translation;
    def = kind ? &*kind : it->second.any ? &*it->second.any : nullptr;
  }
  if (!def && it == defaults_.end()) {
    fail(at, "error '" + err.name + "'" + context +
                 " has no distribution (sigma, normal, uniform or truncnormal) and "
                 "error_defaults has none for its group '" +
                 err.group + "'");
  }
  if (!def) {
    const std::string kind = rotation ? "rotation" : "translation";
    fail(at, "error '" + err.name + "'" + context +
                 " has no distribution (sigma, normal, uniform or truncnormal) and "
                 "error_defaults." +
                 err.group + " has none for a " + kind + " (add " + kind + ": {...} to it)");
  }
  if (!unit_given && !def->unit.empty()) err.unit = def->unit;
  double scale = 1;
  if (!def->unit.empty()) {
    if (table_unit(def->unit).angle != rotation) {
      // The unit as written (µm, not its table spelling um), and the error it does not fit.
      const std::string written =
          def->unit_at.node.IsScalar() ? def->unit_at.node.Scalar() : def->unit;
      fail(def->unit_at,
           "unit '" + written + "' is " + (rotation ? "a length" : "an angle") + " but error '" +
               err.name + "' (line " + std::to_string(loc(at.where).line) + ") is a " +
               (rotation ? "rotation" : "translation") + "; give the group per-kind defaults: " +
               err.group + ": {translation: {..., unit: um}, rotation: {..., unit: urad}}");
    }
    scale = table_unit(def->unit).to_base / table_unit(err.unit).to_base;
  }
  err.distribution = def->distribution;
  err.distribution.a *= scale;
  err.distribution.b *= scale;
  err.distribution.lo *= scale;
  err.distribution.hi *= scale;
}

}  // namespace weilgen::machine_detail
