#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <utility>

#include "loader.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/derived.hpp"
#include "weilgen/machine/pdge_basis.hpp"

namespace weilgen::machine_detail {

void Loader::read_body_errors(int b, const Entry* e) {
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

void Loader::add_error(int b, ErrorDef err) {
  drafts_[static_cast<size_t>(b)].body.errors.push_back(static_cast<int>(errors_.size()));
  errors_.push_back(std::move(err));
}

void Loader::expand_iso(int b, const Field& at, bool implicit) {
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
    err.to_base = table_unit(err.unit).to_base;
    add_error(b, std::move(err));
  }
}

ErrorDef Loader::iso_error(const std::string& name, const IsoError& iso) {
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

ErrorDef Loader::read_error(int b, const Entry& e, const std::string& errors_path) {
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
  err.to_base = table_unit(err.unit).to_base;
  return err;
}

void Loader::require_custom_keys(const MapView& m, const IsoMatch& iso, const std::string& body,
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

void Loader::read_error_effect(const MapView& m, ErrorDef& err, bool iso) const {
  if (const Entry* e = m.find("effect")) {
    err.effect = choice<ErrorEffect>(
        e->value, {{"translation", ErrorEffect::Translation}, {"rotation", ErrorEffect::Rotation}});
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

std::vector<Field> Loader::read_aliases(const MapView& m, ErrorDef& err) const {
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

int Loader::read_sign(const Field& f) const {
  const std::string sign = text(f);
  if (sign == "-1") return -1;
  if (sign != "1" && sign != "+1") fail(f, "sign must be 1 or -1, got '" + sign + "'");
  return 1;
}

void Loader::claim_error_names(const ErrorDef& err, const Field& key,
                               const std::vector<Field>& alias_fields) {
  claim(error_names_, err.name, {"error name", err.name, loc(key.where).line}, key);
  claim_symbol(err.name, "error name", key);
  for (size_t i = 0; i < err.aliases.size(); ++i) {
    const Field& at = alias_fields[i];
    claim(error_names_, err.aliases[i].name, {"alias", err.name, loc(at.where).line}, at);
  }
}

void Loader::check_dimension(const Field& at, const ErrorDef& err,
                             const std::string& unit_name) const {
  const bool angle = table_unit(unit_name).angle;
  const bool rotation = err.effect == ErrorEffect::Rotation;
  if (angle != rotation) {
    // The unit as written (µm, not its table spelling um).
    const std::string written = at.node.IsScalar() ? at.node.Scalar() : unit_name;
    fail(at, "unit '" + written + "' is " + (angle ? "an angle" : "a length") + " but error '" +
                 err.name + "' is a " + (rotation ? "rotation" : "translation"));
  }
}

}  // namespace weilgen::machine_detail
