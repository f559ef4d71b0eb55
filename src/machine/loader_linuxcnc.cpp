// The `linuxcnc:` section of a machine file (machines/README.md, "LinuxCNC"): how a LinuxCNC
// configuration's joints relate to the model's axes. Checks that need every axis together
// (letters and joint numbers used twice, the defaults) are machine/linuxcnc.cpp's.
#include <algorithm>
#include <cmath>

#include "loader.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen::machine_detail {

void Loader::read_linuxcnc(const Field& f) {
  const MapView m = map(f, kLinuxcncKeys);
  LinuxcncSpec& spec = d_.linuxcnc;
  spec.loc = loc(f.where);
  if (const Entry* e = m.find("units")) {
    const std::string u = text(e->value);
    if (u != "mm" && u != "inch")
      fail(e->value, "unknown units '" + u + "' (LinuxCNC's LINEAR_UNITS: mm or inch)");
    spec.linear_units = u;
  }
  const Entry* axes = m.find("axes");
  if (!axes) return;
  std::vector<std::string> coordinates;
  for (int b : d_.axes())
    coordinates.push_back(d_.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  const MapView am = map(axes->value, {}, "axis name");
  for (const Entry& e : am.entries) {
    LinuxcncAxisSpec a;
    a.coordinate = e.key;
    a.loc = loc(e.key_node);
    if (std::find(coordinates.begin(), coordinates.end(), e.key) == coordinates.end())
      fail_at(e.key_node, axes->value.path,
              "'" + e.key + "' is not an axis of the model (axes: " + join(coordinates) + ")");
    const MapView xm = map(e.value, kLinuxcncAxisKeys);
    if (const Entry* s = xm.find("sign")) a.sign = read_sign(s->value);
    if (const Entry* o = xm.find("offset")) a.offset = number(o->value);
    if (const Entry* l = xm.find("letter")) {
      a.letter = text(l->value);
      if (a.letter.size() != 1 || std::string("XYZABCUVW").find(a.letter) == std::string::npos)
        fail(l->value, "letter must be one of X Y Z A B C U V W (trivkins' coordinates), got '" +
                           a.letter + "'");
    }
    if (const Entry* j = xm.find("joint")) {
      const double v = number(j->value);
      if (!(v >= 0 && v <= 15) || v != std::floor(v))
        fail(j->value, "joint must be a whole number 0 ... 15 (LinuxCNC's EMCMOT_MAX_JOINTS - 1)");
      a.joint = static_cast<int>(v);
    }
    spec.axes.push_back(std::move(a));
  }
}

}  // namespace weilgen::machine_detail
