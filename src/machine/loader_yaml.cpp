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
#include "weilgen/machine/cxx_names.hpp"
#include "weilgen/machine/derived.hpp"
#include "weilgen/machine/pdge_basis.hpp"

namespace weilgen::machine_detail {

SourceLoc Loader::loc(const YAML::Node& n) const {
  const YAML::Mark m = n.Mark();
  if (m.is_null() || m.line < 0) return {file_, 0, 0};
  return {file_, m.line + 1, m.column + 1};
}

[[noreturn]] void Loader::fail(const Field& f, const std::string& message) const {
  throw InputError(loc(f.where), f.path.empty() ? message : f.path + ": " + message);
}

[[noreturn]] void Loader::fail_at(const YAML::Node& at, const std::string& path,
                                  const std::string& message) const {
  fail({at, at, path}, message);
}

MapView Loader::map(const Field& f, const std::vector<std::string>& allowed,
                    const char* key_kind) const {
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
    m.entries.push_back({name, key, {value, value.IsNull() ? key : value, sub_path(f.path, name)}});
  }
  return m;
}

const Entry& Loader::required(const MapView& m, const std::string& key) const {
  if (const Entry* e = m.find(key)) return *e;
  fail(m.self, "missing required key '" + key + "'");
}

std::string Loader::text(const Field& f) const {
  if (!f.node.IsScalar()) fail(f, "expected a single value");
  return f.node.Scalar();
}

std::string Loader::identifier(const Field& f, const std::string& what) const {
  const std::string s = f.node.IsScalar() ? f.node.Scalar() : std::string();
  if (!is_identifier(s)) {
    fail(f, what + " '" + s + "' is not an identifier ([A-Za-z_][A-Za-z0-9_]*)");
  }
  // The name becomes a C++ identifier in the generated header.
  if (const std::string why = cxx_name_problem(s); !why.empty())
    fail(f, what + " '" + s + "' " + why + "; choose another name");
  return s;
}

std::string Loader::key_identifier(const Entry& e, const std::string& parent_path,
                                   const std::string& what) const {
  return identifier({e.key_node, e.key_node, parent_path}, what);
}

std::vector<Field> Loader::items(const Field& f, size_t min, size_t max,
                                 const std::string& form) const {
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

Expr Loader::parsed(const Field& f) const {
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

double Loader::finite(const Field& f, double v) const {
  if (!std::isfinite(v)) fail(f, "'" + text(f) + "' is not a finite number");
  return v;
}

double Loader::number(const Field& f) const {
  const Expr e = parsed(f);
  const std::vector<std::string> names = e.params();
  if (!names.empty()) {
    fail(f, "expected a number, got '" + text(f) + "' (parameters such as '" + names[0] +
                "' are allowed only in offsets, points and static angles)");
  }
  return finite(f, e.eval({}));
}

double Loader::positive(const Field& f, const std::string& what) const {
  const double v = number(f);
  if (v <= 0) fail(f, what + " must be positive, got " + text(f));
  return v;
}

Expr Loader::expression(const Field& f) const {
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

std::array<Expr, 3> Loader::point(const Field& f) const {
  const std::vector<Field> xyz = items(f, 3, 3, "[x, y, z]");
  return {expression(xyz[0]), expression(xyz[1]), expression(xyz[2])};
}

Vec3 Loader::direction(const Field& f) const {
  if (f.node.IsScalar()) {
    static const std::vector<std::pair<std::string, Vec3>> named = {
        {"x", {1, 0, 0}},   {"y", {0, 1, 0}},   {"z", {0, 0, 1}},
        {"-x", {-1, 0, 0}}, {"-y", {0, -1, 0}}, {"-z", {0, 0, -1}}};
    for (const auto& [name, v] : named) {
      if (f.node.Scalar() == name) return v;
    }
    fail(f, "unknown direction '" + f.node.Scalar() + "' (x, y, z, -x, -y, -z or [ax, ay, az])");
  }
  const std::vector<Field> xyz = items(f, 3, 3, "a direction: x, y, z, -x, -y, -z or [ax, ay, az]");
  Vec3 v{number(xyz[0]), number(xyz[1]), number(xyz[2])};
  const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (norm == 0) fail(f, "direction must not be zero");
  for (double& c : v) c /= norm;
  return v;
}

void Loader::claim(std::map<std::string, Claim>& names, const std::string& name,
                   const Claim& holder, const Field& at) const {
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
    fail(at, "duplicate " + holder.kind + " '" + name + "': already used as " + what + " at line " +
                 line);
  }
  fail(at, "'" + name + "' is already the name of a " + first.kind + " (line " + line +
               "); parameters, coordinates and error names must be distinct");
}

void Loader::claim_symbol(const std::string& name, const std::string& kind, const Field& at) {
  claim(symbols_, name, {kind, "", loc(at.where).line}, at);
}

}  // namespace weilgen::machine_detail
