#include "weilgen/measure/line6d.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "weilgen/base/text.hpp"

namespace weilgen {
namespace {

constexpr LaserChannel kChannels[kLaserChannels] = {
    LaserChannel::Linear, LaserChannel::StraightnessH, LaserChannel::StraightnessV,
    LaserChannel::Yaw,    LaserChannel::Pitch,         LaserChannel::Roll};

void check_axis(const std::string& axis) {
  if (axis != "X" && axis != "Y" && axis != "Z") {
    throw std::invalid_argument("axis '" + axis +
                                "': 6D line measurements are read for the linear axes X, Y and Z");
  }
}

char rotation_of(char direction) { return direction == 'X' ? 'A' : direction == 'Y' ? 'B' : 'C'; }

ProfileKind kind_of(const std::string& iso) {
  // E_<L><K>
  const char l = iso[2], k = iso[3];
  if (l == k) return ProfileKind::Positioning;
  if (l == 'X' || l == 'Y' || l == 'Z') return ProfileKind::Straightness;
  return ProfileKind::Angular;
}

const LaserChannel* channel_by_column(const std::string& column) {
  for (const LaserChannel& c : kChannels)
    if (column == laser_column(c)) return &c;
  return nullptr;
}

}  // namespace

const char* laser_column(LaserChannel channel) {
  switch (channel) {
    case LaserChannel::Linear:
      return "lin_um";
    case LaserChannel::StraightnessH:
      return "str_h_um";
    case LaserChannel::StraightnessV:
      return "str_v_um";
    case LaserChannel::Yaw:
      return "yaw_urad";
    case LaserChannel::Pitch:
      return "pitch_urad";
    case LaserChannel::Roll:
      return "roll_urad";
  }
  return "?";
}

const char* profile_kind_name(ProfileKind kind) {
  switch (kind) {
    case ProfileKind::Positioning:
      return "positioning";
    case ProfileKind::Straightness:
      return "straightness";
    case ProfileKind::Angular:
      return "angular";
  }
  return "?";
}

std::vector<std::string> line6d_iso_errors(const std::string& axis) {
  check_axis(axis);
  std::vector<std::string> names;
  for (const char* l : {"X", "Y", "Z", "A", "B", "C"})
    names.push_back("E_" + std::string(l) + axis);
  return names;
}

std::string line6d_iso_column(const std::string& iso) {
  return iso + (kind_of(iso) == ProfileKind::Angular ? "_urad" : "_um");
}

std::vector<ChannelMapping> line6d_default_mapping(const std::string& axis) {
  check_axis(axis);
  const char K = axis[0];
  const char H = K == 'X' ? 'Y' : 'X';
  const char V = K == 'Z' ? 'Y' : 'Z';
  auto name = [&](char e) { return std::string("E_") + e + K; };
  const std::string k(1, K), h(1, H), v(1, V);
  return {
      {LaserChannel::Linear, name(K), +1,
       "Table 2: the positioning error is positive along +" + k +
           " (right-handed axes), as in "
           "ISO 230-1"},
      {LaserChannel::StraightnessH, name(H), +1,
       "Table 2: the horizontal straightness is positive along +" + h},
      {LaserChannel::StraightnessV, name(V), +1,
       "Table 2: the vertical straightness is positive along +" + v},
      {LaserChannel::Yaw, name(rotation_of(V)), -1,
       "Table 2: the laser's yaw (about " + v +
           ") is positive against the right-hand rotation about +" + v + " used by ISO 230-1"},
      {LaserChannel::Pitch, name(rotation_of(H)), -1,
       "Table 2: the laser's pitch (about " + h +
           ") is positive against the right-hand rotation about +" + h + " used by ISO 230-1"},
      {LaserChannel::Roll, name(rotation_of(K)), +1,
       "Table 2: the laser's roll (about " + k + ") follows the right-hand rule about +" + k},
  };
}

std::vector<ChannelMapping> apply_line6d_map(std::vector<ChannelMapping> mapping,
                                             const std::string& axis, const std::string& text) {
  const std::vector<std::string> iso = line6d_iso_errors(axis);
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t comma = text.find(',', start);
    if (comma == std::string::npos) comma = text.size();
    const std::string item = trim(text.substr(start, comma - start));
    start = comma + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    const std::string quoted = "map item \"" + item + "\": ";
    if (eq == std::string::npos)
      throw std::invalid_argument(quoted + "expected CHANNEL=[-]ERROR, e.g. yaw_urad=-E_C" + axis);
    const std::string col = trim(item.substr(0, eq));
    std::string target = trim(item.substr(eq + 1));
    int sign = 1;
    if (!target.empty() && (target[0] == '-' || target[0] == '+')) {
      sign = target[0] == '-' ? -1 : 1;
      target = trim(target.substr(1));
    }
    const LaserChannel* ch = channel_by_column(col);
    if (!ch) {
      throw std::invalid_argument(quoted + "unknown channel '" + col +
                                  "' (expected lin_um, str_h_um, str_v_um, yaw_urad, pitch_urad "
                                  "or roll_urad)");
    }
    if (std::find(iso.begin(), iso.end(), target) == iso.end()) {
      throw std::invalid_argument(quoted + "'" + target + "' is not an error of axis " + axis +
                                  " (expected one of " + join(iso) + ")");
    }
    const bool angular_channel =
        *ch == LaserChannel::Yaw || *ch == LaserChannel::Pitch || *ch == LaserChannel::Roll;
    if (angular_channel != (kind_of(target) == ProfileKind::Angular)) {
      throw std::invalid_argument(quoted + "channel '" + col + "' is " +
                                  (angular_channel ? "an angle" : "a length") + " but " + target +
                                  " is " + (angular_channel ? "a translation" : "a rotation"));
    }
    for (ChannelMapping& m : mapping) {
      if (m.channel == *ch) {
        m.iso = target;
        m.sign = sign;
        m.why = "# map: " + item;
      }
    }
  }
  std::set<std::string> seen;
  for (const ChannelMapping& m : mapping) {
    if (!seen.insert(m.iso).second) {
      throw std::invalid_argument("map \"" + text + "\": two channels go to " + m.iso +
                                  " (each of the six errors takes one channel)");
    }
  }
  return mapping;
}

ReferenceLine least_squares_line(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size())
    throw std::invalid_argument("reference line: positions and values differ in number");
  double n = 0, mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isnan(y[i])) continue;
    n += 1;
    mx += (x[i] - mx) / n;
    my += (y[i] - my) / n;
  }
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isnan(y[i])) continue;
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (!(sxx > 0)) {
    throw std::invalid_argument(
        "reference line: a straightness profile needs values at two "
        "distinct positions at least");
  }
  ReferenceLine line;
  line.slope = sxy / sxx;
  line.intercept = my - line.slope * mx;
  return line;
}

std::vector<double> remove_reference_line(const std::vector<double>& x,
                                          const std::vector<double>& y, ReferenceLine* line) {
  const ReferenceLine l = least_squares_line(x, y);
  std::vector<double> out(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) out[i] = y[i] - l.at(x[i]);
  if (line) *line = l;
  return out;
}

const Line6dProfile* Line6dData::find(const std::string& error) const {
  for (const Line6dProfile& p : profiles)
    if (p.error == error) return &p;
  return nullptr;
}

Line6dData convert_line6d(const std::string& axis, const std::vector<double>& position,
                          const std::map<std::string, std::vector<double>>& columns,
                          const std::vector<ChannelMapping>& mapping,
                          const Line6dOptions& options) {
  const std::vector<std::string> iso = line6d_iso_errors(axis);
  for (double p : position)
    if (!std::isfinite(p)) throw std::invalid_argument("line6d: a position is not finite");
  // Every column must be a laser channel or one of this axis' ISO columns.
  for (const auto& [name, v] : columns) {
    if (v.size() != position.size()) {
      throw std::invalid_argument("line6d: column " + name + " has " + std::to_string(v.size()) +
                                  " values for " + std::to_string(position.size()) + " positions");
    }
    bool known = channel_by_column(name) != nullptr;
    for (const std::string& e : iso) known = known || name == line6d_iso_column(e);
    if (!known) {
      throw std::invalid_argument("line6d: column '" + name + "' is neither a laser channel " +
                                  "(lin_um, str_h_um, str_v_um, yaw_urad, pitch_urad, roll_urad) " +
                                  "nor an error of axis " + axis + " (" +
                                  line6d_iso_column(iso[0]) + " ... " + line6d_iso_column(iso[5]) +
                                  ")");
    }
  }
  Line6dData d;
  d.axis = axis;
  d.position = position;
  bool laser = false, isos = false;
  for (const std::string& e : iso) {
    const ChannelMapping* m = nullptr;
    for (const ChannelMapping& c : mapping)
      if (c.iso == e && columns.count(laser_column(c.channel))) m = &c;
    const std::string iso_col = line6d_iso_column(e);
    const bool has_iso = columns.count(iso_col) != 0;
    if (m && has_iso) {
      throw std::invalid_argument("line6d: " + e + " is given twice, as " +
                                  laser_column(m->channel) + " (laser channel) and as " + iso_col);
    }
    if (!m && !has_iso) continue;
    Line6dProfile p;
    p.error = e;
    p.kind = kind_of(e);
    p.unit = p.kind == ProfileKind::Angular ? "urad" : "um";
    p.source = m ? laser_column(m->channel) : iso_col;
    p.sign = m ? m->sign : 1;
    const std::vector<double>& src = columns.at(p.source);
    bool any = false;
    for (double v : src) {
      p.raw.push_back(p.sign * v);
      any = any || !std::isnan(v);
    }
    if (!any) continue;  // an empty column: not measured
    (m ? laser : isos) = true;
    p.removed = "none";
    p.values = p.raw;
    if (p.kind == ProfileKind::Straightness && options.remove_straightness_line) {
      try {
        p.values = remove_reference_line(position, p.raw, &p.reference);
      } catch (const std::invalid_argument& ex) {
        throw std::invalid_argument("line6d: " + e + " (" + p.source + "): " + ex.what());
      }
      p.removed = "line";
    } else if (p.kind == ProfileKind::Angular && options.angular == AngularReference::Mean) {
      double n = 0, mean = 0;
      for (double v : p.raw)
        if (!std::isnan(v)) n += 1, mean += (v - mean) / n;
      p.reference.intercept = mean;
      for (double& v : p.values) v -= mean;
      p.removed = "mean";
    }
    d.profiles.push_back(std::move(p));
  }
  d.spelling = laser && isos ? "mixed" : laser ? "laser" : "iso";
  return d;
}

bool is_line6d(const MeasurementTable& table) {
  return lower(trim(table.header_key("format"))) == "line6d";
}

ReadOptions line6d_read_options() {
  ReadOptions o;
  for (const LaserChannel& c : kChannels) o.expected.push_back(laser_column(c));
  for (const char* axis : {"X", "Y", "Z"})
    for (const std::string& e : line6d_iso_errors(axis)) o.expected.push_back(line6d_iso_column(e));
  return o;
}

Line6dData line6d_from_table(const MeasurementTable& table, const Line6dOptions& options) {
  auto key_loc = [&](const std::string& key) {
    const auto it = table.header_key_lines.find(key);
    return SourceLoc{table.file, it == table.header_key_lines.end() ? 0 : it->second, 0};
  };
  const SourceLoc header{table.file, table.header_line, 0};
  const std::string axis = trim(table.header_key("axis"));
  if (axis.empty()) {
    throw InputError(SourceLoc{table.file, 0, 0},
                     "line6d: the header key '# axis:' is missing (the measured axis, e.g. "
                     "'# axis: X')");
  }
  std::vector<ChannelMapping> mapping;
  try {
    mapping = line6d_default_mapping(axis);
  } catch (const std::invalid_argument& e) {
    throw InputError(key_loc("axis"), std::string("line6d: ") + e.what());
  }
  if (table.header_keys.count("map")) {
    try {
      mapping = apply_line6d_map(mapping, axis, table.header_key("map"));
    } catch (const std::invalid_argument& e) {
      throw InputError(key_loc("map"), std::string("line6d: ") + e.what());
    }
  }
  if (!table.has(axis)) {
    throw InputError(header, "line6d: the axis column '" + axis +
                                 "' (the position along the axis, mm) is missing");
  }
  const std::vector<double>& pos = table.column(axis);
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (std::isnan(pos[i])) {
      throw InputError(table.cell(i, axis), "line6d: the position '" + axis + "' is empty");
    }
  }
  const std::vector<std::string> iso = line6d_iso_errors(axis);
  std::map<std::string, std::vector<double>> cols;
  for (const std::string& name : table.columns) {
    if (channel_by_column(name)) {
      cols[name] = table.column(name);
      continue;
    }
    bool mine = false;
    for (const std::string& e : iso) mine = mine || name == line6d_iso_column(e);
    if (mine) {
      cols[name] = table.column(name);
      continue;
    }
    if (name.size() > 4 && name.compare(0, 2, "E_") == 0) {
      throw InputError(header, "line6d: column '" + name + "' is an error of axis " +
                                   name.substr(3, 1) + " but this file measures axis " + axis +
                                   " ('# axis: " + axis + "')");
    }
    if (table.info_of(name).role == ColumnRole::Deviation) {
      throw InputError(header, "line6d: column '" + name +
                                   "' is a point-measurement deviation; a line6d file holds the "
                                   "six errors of one axis (docs/data-format.md)");
    }
  }
  if (cols.empty()) {
    throw InputError(header,
                     "line6d: no 6D column (expected lin_um, str_h_um, str_v_um, "
                     "yaw_urad, pitch_urad, roll_urad or " +
                         line6d_iso_column(iso[0]) + " ... " + line6d_iso_column(iso[5]) + ")");
  }
  Line6dData d;
  try {
    d = convert_line6d(axis, pos, cols, mapping, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(SourceLoc{table.file, 0, 0}, e.what());
  }
  d.file = table.file;
  if (table.has("cycle")) {
    const std::vector<double>& c = table.column("cycle");
    for (std::size_t i = 0; i < c.size(); ++i) {
      if (std::isnan(c[i]) || c[i] != std::floor(c[i])) {
        throw InputError(table.cell(i, "cycle"), "line6d: the cycle must be a whole number");
      }
      d.cycle.push_back(static_cast<int>(c[i]));
    }
  }
  return d;
}

Line6dData read_line6d(const std::string& path, const Line6dOptions& options) {
  const MeasurementTable table = read_measurements(path, line6d_read_options());
  if (!is_line6d(table)) {
    throw InputError(SourceLoc{path, 0, 0},
                     "not a 6D line measurement: the header key '# format: line6d' is missing");
  }
  return line6d_from_table(table, options);
}

}  // namespace weilgen
