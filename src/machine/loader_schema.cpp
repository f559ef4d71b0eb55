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

void Loader::read_version(const Entry& e) {
  if (!e.value.node.IsScalar() || e.value.node.Scalar() != "1") {
    const std::string got = e.value.node.IsScalar() ? e.value.node.Scalar() : "?";
    fail(e.value, "unsupported format version '" + got + "' (this weilgen reads weilgen: 1)");
  }
}

void Loader::read_parameters(const Field& f) {
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

std::optional<Unit> Loader::unit(const Field& f, const std::vector<std::string>& allowed) const {
  const std::string s = text(f);
  const std::string name = ascii_unit(s);
  if (std::find(allowed.begin(), allowed.end(), name) == allowed.end())
    fail(f, "unknown unit '" + s + "' (allowed: " + join(allowed) + ")");
  return table_unit(name);
}

void Loader::read_groups(const Field& f) {
  for (const Field& item : items(f, 0, SIZE_MAX, "a list of group names")) {
    const std::string g = identifier(item, "group name");
    // Re-declaring a built-in group is harmless (the README's own example does).
    if (!has_group(g)) d_.groups.push_back(g);
  }
}

bool Loader::has_group(const std::string& g) const {
  return std::find(d_.groups.begin(), d_.groups.end(), g) != d_.groups.end();
}

std::string Loader::known_group(const Field& f) const {
  const std::string g = text(f);
  if (!has_group(g)) {
    fail(f, "unknown group '" + g + "' (known: " + join(d_.groups) +
                "; declare more under 'groups:')");
  }
  return g;
}

std::optional<Distribution> Loader::read_distribution(const MapView& m) const {
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

void Loader::check_interval(const Field& f, double lo, double hi) const {
  if (lo >= hi)
    fail(f, "lo (" + format_short(lo) + ") must be less than hi (" + format_short(hi) + ")");
}

}  // namespace weilgen::machine_detail
