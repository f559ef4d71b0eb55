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

void Loader::read_bodies(const Entry& bodies) {
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

void Loader::read_body(int b, const Entry& e) {
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

Offset Loader::read_offset(const Field& f) const {
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

Joint Loader::read_joint(const Entry& e) {
  const MapView m = map(e.value, kJointKeys);
  Joint j;
  j.loc = loc(e.key_node);
  const Entry* twist = m.find("twist");
  const Entry* type = m.find("type");
  if (!type && !twist) fail(m.self, "missing required key 'type' (or give the joint as a 'twist')");
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
  // The generated code names the cosine and sine of an angle cos_<coordinate>, sin_<coordinate>.
  claim_symbol("cos_" + j.coordinate, "cosine of coordinate " + j.coordinate + " (generated code)",
               coordinate);
  claim_symbol("sin_" + j.coordinate, "sine of coordinate " + j.coordinate + " (generated code)",
               coordinate);
  const std::vector<std::string>& units =
      j.type == JointType::Prismatic ? kPrismaticUnits : kRevoluteUnits;
  std::optional<Unit> u = table_unit(units.front());
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

std::vector<Field> Loader::twist_fields(const Field& f, Vec3& w) const {
  std::vector<Field> xi = items(f, 6, 6, "a twist [wx, wy, wz, vx, vy, vz]");
  w = {number(xi[0]), number(xi[1]), number(xi[2])};
  const double wn = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  if (wn != 0 && std::abs(wn - 1) > 1e-9)
    fail(f, "w must be a unit vector or zero, |w| = " + format_short(wn));
  return xi;
}

void Loader::read_twist(const Field& f, std::optional<JointType> declared, Joint& j) const {
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
        fail(f,
             "a prismatic twist (w = 0) has a unit direction v of numbers, not '" + c.str() + "'");
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

void Loader::link_parents() {
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

int Loader::draft_index(const std::string& name) const {
  for (size_t i = 0; i < drafts_.size(); ++i) {
    if (drafts_[i].body.name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::string> Loader::draft_names() const {
  std::vector<std::string> names;
  for (const BodyDraft& d : drafts_) names.push_back(d.body.name);
  return names;
}

int Loader::single_base(const Entry& bodies) const {
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

void Loader::check_cycles(int base) const {
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

std::vector<int> Loader::tree_order(int base) const {
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

void Loader::apply_order(const std::vector<int>& order) {
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

}  // namespace weilgen::machine_detail
