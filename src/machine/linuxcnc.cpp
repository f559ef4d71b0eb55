#include "weilgen/machine/linuxcnc.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "weilgen/base/error.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"

namespace weilgen {

namespace {

// trivkins' letters in its default order (coordinates=XYZABCUVW).
const std::string kLetters = "XYZABCUVW";

// The base-frame direction a letter names: X, U, A along x; Y, V, B along y; Z, W, C along z.
int letter_direction(char letter) { return static_cast<int>(kLetters.find(letter) % 3); }

bool is_rotary_letter(char letter) { return letter == 'A' || letter == 'B' || letter == 'C'; }

// The independent axes' coordinate names, kAxes order.
std::vector<std::string> axis_names(const Description& desc) {
  std::vector<std::string> names;
  for (int b : desc.axes())
    names.push_back(desc.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  return names;
}

std::size_t axis_index(const Description& desc, const std::string& name, const std::string& flag) {
  const std::vector<std::string> names = axis_names(desc);
  const auto at = std::find(names.begin(), names.end(), name);
  if (at == names.end())
    throw std::invalid_argument(flag + ": '" + name + "' is not an axis of " + desc.name +
                                " (axes: " + join(names) + ")");
  return static_cast<std::size_t>(at - names.begin());
}

// "X=-1,Y=1" items as (axis, text).
std::vector<std::pair<std::string, std::string>> assignments(const Description& desc,
                                                             const std::string& text,
                                                             const std::string& flag) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& raw : split(text, ',')) {
    const std::string item = trim(raw);
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument(flag + " " + quoted(item) + ": expected AXIS=VALUE");
    const std::string name = trim(item.substr(0, eq));
    axis_index(desc, name, flag + " " + quoted(item));
    for (const auto& [seen, v] : out)
      if (seen == name) throw std::invalid_argument(flag + ": axis " + name + " given twice");
    out.emplace_back(name, trim(item.substr(eq + 1)));
  }
  return out;
}

}  // namespace

int LinuxcncMapping::axis_of_joint(int j) const {
  for (std::size_t i = 0; i < axes.size(); ++i)
    if (axes[i].joint == j) return static_cast<int>(i);
  return -1;
}

std::vector<std::pair<std::string, int>> parse_linuxcnc_signs(const Description& desc,
                                                              const std::string& text) {
  std::vector<std::pair<std::string, int>> out;
  for (const auto& [name, value] : assignments(desc, text, "--sign")) {
    if (value != "1" && value != "+1" && value != "-1")
      throw std::invalid_argument("--sign " + name + "=" + value + ": a sign is 1 or -1");
    out.emplace_back(name, value == "-1" ? -1 : 1);
  }
  return out;
}

std::vector<std::pair<std::string, double>> parse_linuxcnc_offsets(const Description& desc,
                                                                   const std::string& text) {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& [name, value] : assignments(desc, text, "--offset")) {
    const Joint& j =
        desc.bodies[static_cast<std::size_t>(desc.axes()[axis_index(desc, name, "--offset")])]
            .joint;
    const Quantity q = parse_quantity_unit(value, j.unit, "--offset " + name);
    if (q.unit.angle != (j.type == JointType::Revolute))
      throw std::invalid_argument("--offset " + name + "=" + value + ": " + name + " is in " +
                                  j.unit + ", not " + q.unit_name);
    out.emplace_back(name, q.value() / j.to_base);
  }
  return out;
}

LinuxcncMapping linuxcnc_mapping(const Description& desc, const LinuxcncOverrides& overrides) {
  const LinuxcncSpec& spec = desc.linuxcnc;
  const SourceLoc at = spec.loc.file.empty() ? SourceLoc{desc.source_file, 0, 0} : spec.loc;
  LinuxcncMapping m;
  m.linear_units = !overrides.units.empty()    ? overrides.units
                   : spec.linear_units.empty() ? "mm"
                                               : spec.linear_units;
  if (m.linear_units != "mm" && m.linear_units != "inch")
    throw std::invalid_argument("--units " + m.linear_units + ": mm or inch");
  const std::vector<int> bodies = desc.axes();
  std::vector<int> workpiece_chain;
  if (!desc.output && desc.workpiece.body >= 0)
    workpiece_chain = desc.chain_to(desc.workpiece.body);
  const auto spec_of = [&](const std::string& name) -> const LinuxcncAxisSpec* {
    for (const auto& a : spec.axes)
      if (a.coordinate == name) return &a;
    return nullptr;
  };

  // Letters: as written; else the coordinate when it is a letter; else its first character when
  // free; else the first free of U V W (linear) or A B C (rotary).
  std::string taken;
  m.axes.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(bodies[i])].joint;
    LinuxcncJoint& x = m.axes[i];
    x.coordinate = j.coordinate;
    x.axis = i;
    x.rotary = j.type == JointType::Revolute;
    x.model_unit = j.unit;
    x.travel_min = j.min;
    x.travel_max = j.max;
    const LinuxcncAxisSpec* s = spec_of(j.coordinate);
    std::string letter = s && !s->letter.empty() ? s->letter : "";
    if (letter.empty() && j.coordinate.size() == 1 &&
        kLetters.find(j.coordinate) != std::string::npos)
      letter = j.coordinate;
    if (!letter.empty()) {
      if (taken.find(letter[0]) != std::string::npos)
        throw InputError(s && !s->letter.empty() ? s->loc : at,
                         "linuxcnc: two axes have the letter " + letter +
                             " (give each axis its own letter under linuxcnc: axes:)");
      x.letter = letter[0];
      taken += letter;
    } else {
      x.letter = 0;
    }
  }
  for (LinuxcncJoint& x : m.axes) {
    if (x.letter) continue;
    const std::string first = x.coordinate.substr(0, 1);
    const std::string candidates =
        (kLetters.find(first) != std::string::npos && is_rotary_letter(first[0]) == x.rotary)
            ? first + (x.rotary ? "ABC" : "UVW")
            : std::string(x.rotary ? "ABC" : "UVW");
    for (char c : candidates)
      if (taken.find(c) == std::string::npos) {
        x.letter = c;
        break;
      }
    if (!x.letter)
      throw InputError(at, "linuxcnc: no free axis letter for " + x.coordinate +
                               " (give it one under linuxcnc: axes: " + x.coordinate +
                               ": {letter: ...})");
    taken += x.letter;
  }

  // Joint numbers: as written, the others in trivkins' letter order after them.
  std::vector<int> used(16, -1);
  for (LinuxcncJoint& x : m.axes) {
    const LinuxcncAxisSpec* s = spec_of(x.coordinate);
    x.joint = -1;
    if (s && s->joint) {
      if (used[static_cast<std::size_t>(*s->joint)] >= 0)
        throw InputError(s->loc,
                         "linuxcnc: joint " + std::to_string(*s->joint) + " is given to two axes");
      x.joint = *s->joint;
      used[static_cast<std::size_t>(x.joint)] = static_cast<int>(x.axis);
    }
  }
  std::vector<std::size_t> order(m.axes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return kLetters.find(m.axes[a].letter) < kLetters.find(m.axes[b].letter);
  });
  std::size_t next = 0;
  for (std::size_t i : order) {
    if (m.axes[i].joint >= 0) continue;
    while (used[next] >= 0) ++next;
    m.axes[i].joint = static_cast<int>(next);
    used[next] = static_cast<int>(i);
  }
  m.num_joints = static_cast<int>(m.axes.size());
  for (int j = 0; j < m.num_joints; ++j) {
    const int a = used[static_cast<std::size_t>(j)];
    if (a < 0)
      throw InputError(at, "linuxcnc: joint numbers must be 0 ... " +
                               std::to_string(m.num_joints - 1) + " without gaps (joint " +
                               std::to_string(j) + " has no axis)");
    m.coordinates += m.axes[static_cast<std::size_t>(a)].letter;
  }

  // Signs, offsets, scales.
  const double linear_to_base = parse_unit(m.linear_units).to_base;
  for (LinuxcncJoint& x : m.axes) {
    const Body& body = desc.bodies[static_cast<std::size_t>(bodies[x.axis])];
    const Joint& j = body.joint;
    const bool workpiece = std::find(workpiece_chain.begin(), workpiece_chain.end(),
                                     bodies[x.axis]) != workpiece_chain.end();
    x.sign = workpiece ? -1 : 1;
    x.sign_reason = workpiece ? "carries the workpiece" : "carries the tool";
    if (j.axis[static_cast<std::size_t>(letter_direction(x.letter))] < -0.5) {
      x.sign = -x.sign;
      x.sign_reason += ", its joint axis points against " + std::string(1, x.letter);
    }
    const LinuxcncAxisSpec* s = spec_of(x.coordinate);
    if (s && s->sign) x.sign = *s->sign, x.sign_reason = "machine file";
    if (s && s->offset) x.offset = *s->offset;
    for (const auto& [name, sign] : overrides.signs)
      if (name == x.coordinate) x.sign = sign, x.sign_reason = "--sign";
    for (const auto& [name, offset] : overrides.offsets)
      if (name == x.coordinate) x.offset = offset;
    x.unit = x.rotary ? "deg" : m.linear_units;
    x.scale = (x.rotary ? parse_unit("deg").to_base : linear_to_base) / j.to_base;
  }
  return m;
}

}  // namespace weilgen
