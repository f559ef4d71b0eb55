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
#include "weilgen/machine/algebra_size.hpp"
#include "weilgen/machine/derived.hpp"
#include "weilgen/machine/pdge_basis.hpp"

namespace weilgen::machine_detail {

void Loader::read_points(const Field& f) {
  const MapView m = map(f, {}, "point name");
  for (const Entry& e : m.entries) {
    ChainPoint p;
    p.name = key_identifier(e, f.path, "point name");
    claim_symbol(p.name, "chain point", {e.key_node, e.key_node, f.path});
    p.at = read_point_spec(e.value);
    d_.points.push_back(std::move(p));
  }
}

void Loader::read_directions(const Field& f) {
  const MapView m = map(f, {}, "direction name");
  for (const Entry& e : m.entries) {
    ChainDirection dir;
    dir.name = key_identifier(e, f.path, "direction name");
    claim_symbol(dir.name, "chain direction", {e.key_node, e.key_node, f.path});
    const MapView dm = map(e.value, kDirectionKeys);
    dir.loc = loc(e.value.where);
    dir.body = body_ref(required(dm, "body").value);
    dir.direction = direction(required(dm, "direction").value);
    d_.directions.push_back(std::move(dir));
  }
}

void Loader::read_derived(const Field& f) {
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

OutputTransform Loader::read_output(const Field& f) const {
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

std::array<Expr, 3> Loader::point_formula(const Field& f) const {
  const std::vector<Field> xyz = items(f, 3, 3, "[x, y, z]");
  return {parsed(xyz[0]), parsed(xyz[1]), parsed(xyz[2])};
}

int Loader::body_ref(const Field& body) const {
  const int b = d_.body_index(text(body));
  if (b < 0) fail(body, "unknown body '" + text(body) + "' (bodies: " + join(draft_names()) + ")");
  return b;
}

PointSpec Loader::read_point_spec(const Field& f) const {
  const MapView m = map(f, kPointKeys);
  PointSpec p;
  p.loc = loc(f.where);
  p.body = body_ref(required(m, "body").value);
  if (const Entry* pt = m.find("point")) p.point = point(pt->value);
  return p;
}

void Loader::read_algebra(const Field& f) {
  const MapView m = map(f, kAlgebraKeys);
  if (const Entry* o = m.find("order")) d_.algebra.order = read_order(o->value);
  if (const Entry* r = m.find("relations")) {
    for (const Field& item : items(r->value, 0, SIZE_MAX, "a list of relations")) {
      d_.algebra.relations.push_back(read_relation(item));
    }
  }
}

int Loader::read_order(const Field& f) const {
  const std::string s = text(f);
  int order = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), order);
  if (ec != std::errc() || end != s.data() + s.size()) {
    fail(f, "order must be a whole number from 1 to " + std::to_string(kMaxAlgebraOrder) +
                ", got '" + s + "'");
  }
  if (order < 1 || order > kMaxAlgebraOrder)
    fail(f, "order must be a whole number from 1 to " + std::to_string(kMaxAlgebraOrder) +
                ", got " + s);
  try {
    check_algebra_size(d_, order, "order " + s);  // errors are read before the algebra
  } catch (const std::invalid_argument& e) {
    fail(f, e.what());
  }
  return order;
}

Relation Loader::read_relation(const Field& f) const {
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

std::vector<std::string> Loader::error_names(const std::vector<Field>& fields) const {
  std::vector<std::string> names;
  for (const Field& f : fields) {
    const int i = d_.error_index(text(f));
    if (i < 0) fail(f, "relation names no error '" + text(f) + "'");
    names.push_back(d_.errors[static_cast<size_t>(i)].name);
  }
  return names;
}

std::vector<std::string> Loader::group_names(const std::vector<Field>& fields) const {
  std::vector<std::string> names;
  for (const Field& f : fields) {
    if (!has_group(text(f))) {
      fail(f, "relation names no group '" + text(f) + "' (known: " + join(d_.groups) + ")");
    }
    names.push_back(text(f));
  }
  return names;
}

}  // namespace weilgen::machine_detail
