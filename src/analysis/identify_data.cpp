// The observations identify reads (docs/identify.md, "Data"): point measurements, ballbar traces
// and 6D line files, each with the set-up references its instrument leaves undetermined.
#include <cmath>
#include <limits>
#include <stdexcept>

#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/analysis/identify.hpp"
#include "weilgen/analysis/prediction.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/measure/line6d.hpp"

namespace weilgen {

void PointData::append(PointData other) {
  const std::size_t row_base = poses.size(), obs_base = observations.size();
  for (auto& p : other.poses) poses.push_back(std::move(p));
  for (PointObservation ob : other.observations) {
    ob.row += row_base;
    observations.push_back(ob);
  }
  for (ObservationReference r : other.references) {
    for (std::size_t& i : r.observations) i += obs_base;
    references.push_back(std::move(r));
  }
  for (std::size_t o = 0; o < kObservationKinds; ++o) count[o] += other.count[o];
  file += (file.empty() ? "" : ", ") + other.file;
}

PointData point_data(const MeasurementTable& table, const Description& desc) {
  PointData out;
  out.file = table.file;
  std::vector<const std::vector<double>*> dev(6, nullptr);
  bool any = false;
  for (int o = 0; o < 6; ++o)
    if (table.has(kDeviationColumns[o])) dev[o] = &table.column(kDeviationColumns[o]), any = true;
  if (!any)
    throw InputError(SourceLoc{table.file, table.header_line, 0},
                     "no deviation column (dx_um, dy_um, dz_um, da_urad, db_urad, dc_urad; "
                     "columns: " +
                         join(table.columns) + ")");
  std::vector<std::string> names;
  std::vector<const std::vector<double>*> coord;
  for (int b : desc.axes()) {
    names.push_back(desc.bodies[static_cast<std::size_t>(b)].joint.coordinate);
    coord.push_back(&table.column(names.back()));
  }
  out.poses.assign(table.rows(), std::vector<double>(names.size(), kNaN));
  for (std::size_t r = 0; r < table.rows(); ++r) {
    bool measured = false;
    for (int o = 0; o < 6; ++o) measured = measured || (dev[o] && std::isfinite((*dev[o])[r]));
    if (!measured) continue;
    for (std::size_t a = 0; a < names.size(); ++a) {
      const double v = (*coord[a])[r];
      if (!std::isfinite(v))
        throw InputError(table.cell(r, names[a]),
                         "column '" + names[a] +
                             "' is empty but a deviation is measured (every "
                             "observation needs the machine's coordinates)");
      out.poses[r][a] = v;
    }
    for (int o = 0; o < 6; ++o) {
      if (!dev[o] || !std::isfinite((*dev[o])[r])) continue;
      PointObservation ob;
      ob.row = r;
      ob.line = table.lines[r];
      ob.output = o;
      ob.value = (*dev[o])[r];
      out.observations.push_back(ob);
      ++out.count[static_cast<std::size_t>(o)];
    }
  }
  if (out.observations.empty())
    throw InputError(SourceLoc{table.file, 0, 0},
                     "no observations (no row has a measured deviation)");
  return out;
}

PointData ballbar_point_data(const MeasurementTable& t, const Description& desc,
                             const BallbarFlags& flags, const std::vector<double>& parameters,
                             std::optional<BallbarCircle>& circle) {
  const BallbarMachine machine = ballbar_machine(desc, parameters);
  circle = parse_ballbar_circle(t, machine, flags);
  if (!t.has("angle_deg"))
    throw InputError(SourceLoc{t.file, t.header_line, 0},
                     "a ballbar trace needs an 'angle_deg' column beside 'dr_um' (columns: " +
                         join(t.columns) + ")");
  if (!t.has("dr_um"))
    throw InputError(SourceLoc{t.file, t.header_line, 0},
                     "a ballbar trace needs a 'dr_um' column beside 'angle_deg' (columns: " +
                         join(t.columns) + ")");
  const std::vector<double>& angle = t.column("angle_deg");
  const std::vector<double>& dr = t.column("dr_um");
  PointData p;
  p.file = t.file;
  p.poses.assign(t.rows(), {});
  std::vector<double> angles;  // of the measured rows, for one call to ballbar_directions
  for (std::size_t r = 0; r < t.rows(); ++r) {
    if (!std::isfinite(dr[r])) continue;
    if (!std::isfinite(angle[r]))
      throw InputError(t.cell(r, "angle_deg"), "column 'angle_deg' is empty but dr_um is measured");
    p.poses[r] = ballbar_pose(machine, *circle, angle[r]);
    PointObservation ob;
    ob.row = r;
    ob.line = t.lines[r];
    ob.output = kRadialOutput;
    ob.value = dr[r];
    p.observations.push_back(ob);
    angles.push_back(angle[r]);
  }
  if (p.observations.empty())
    throw InputError(SourceLoc{t.file, 0, 0}, "no observations (no row has a measured dr_um)");
  const std::vector<std::array<double, 3>> u = ballbar_directions(machine, *circle, angles);
  for (std::size_t i = 0; i < u.size(); ++i) p.observations[i].radial = u[i];
  p.count[kRadialOutput] = p.observations.size();
  return p;
}

ObservationReference ballbar_centre_reference(const PointData& data,
                                              const std::vector<double>& angles_deg) {
  ObservationReference ref;
  ref.what = "ballbar centre of " + data.file;
  ref.basis.assign(2, {});
  for (std::size_t i = 0; i < data.observations.size(); ++i) {
    ref.observations.push_back(i);
    const double t = angles_deg[i] * kPi / 180;
    ref.basis[0].push_back(std::cos(t));
    ref.basis[1].push_back(std::sin(t));
  }
  return ref;
}

PointData line6d_point_data(const MeasurementTable& table, const Description& desc,
                            const std::function<void(const std::string&)>& warn) {
  const Line6dData d = line6d_from_table(table, {});
  const std::vector<int> axes = desc.axes();
  int axis = -1;
  for (std::size_t a = 0; a < axes.size(); ++a) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(axes[a])].joint;
    if (j.coordinate == d.axis && j.type == JointType::Prismatic) axis = static_cast<int>(a);
  }
  const auto it = table.header_key_lines.find("axis");
  const SourceLoc axis_loc{table.file, it == table.header_key_lines.end() ? 0 : it->second, 0};
  if (axis < 0) {
    std::vector<std::string> linear;
    for (int b : axes)
      if (desc.bodies[static_cast<std::size_t>(b)].joint.type == JointType::Prismatic)
        linear.push_back(desc.bodies[static_cast<std::size_t>(b)].joint.coordinate);
    throw InputError(axis_loc, "line6d: axis '" + d.axis + "' is not a linear axis of machine " +
                                   desc.name + " (its linear axes: " + join(linear) + ")");
  }
  PointData p;
  p.file = table.file;
  std::vector<double> middle;
  for (int b : axes) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(b)].joint;
    middle.push_back(j.max > j.min ? (j.min + j.max) / 2 : 0.0);
  }
  p.poses.assign(d.position.size(), middle);
  for (std::size_t r = 0; r < d.position.size(); ++r)
    p.poses[r][static_cast<std::size_t>(axis)] = d.position[r];
  const int body = axes[static_cast<std::size_t>(axis)];
  for (const Line6dProfile& prof : d.profiles) {
    const int k = desc.error_index(prof.error);
    if (k < 0 || desc.errors[static_cast<std::size_t>(k)].body != body) {
      if (warn)
        warn(table.file + ": line6d: " + prof.error + " (" + prof.source + ") is not an error of " +
             d.axis + " in machine " + desc.name + ": its profile is not used");
      continue;
    }
    const int kind = prof.kind == ProfileKind::Positioning    ? kLinePositioning
                     : prof.kind == ProfileKind::Straightness ? kLineStraightness
                                                              : kLineAngular;
    ObservationReference ref;
    ref.what = prof.error + " " + prof.removed + " of " + table.file;
    if (prof.removed != "none") ref.basis.assign(prof.removed == "line" ? 2 : 1, {});
    for (std::size_t r = 0; r < prof.values.size(); ++r) {
      if (!std::isfinite(prof.values[r])) continue;
      PointObservation ob;
      ob.row = r;
      ob.line = table.lines[r];
      ob.output = kind;
      ob.value = prof.values[r];
      ob.error = k;
      ref.observations.push_back(p.observations.size());
      if (!ref.basis.empty()) ref.basis[0].push_back(1.0);
      if (ref.basis.size() > 1) ref.basis[1].push_back(d.position[r]);
      p.observations.push_back(ob);
      ++p.count[static_cast<std::size_t>(kind)];
    }
    if (!ref.basis.empty()) p.references.push_back(std::move(ref));
  }
  if (p.observations.empty())
    throw InputError(SourceLoc{table.file, table.header_line, 0},
                     "line6d: no profile of an error of " + d.axis + " in machine " + desc.name);
  return p;
}

void add_rtest_references(PointData& data) {
  for (int o = 0; o < 6; ++o) {
    ObservationReference ref;
    ref.what = std::string("R-test zero of ") + output_name(static_cast<std::size_t>(o)) + " in " +
               data.file;
    ref.basis.assign(1, {});
    for (std::size_t i = 0; i < data.observations.size(); ++i) {
      if (data.observations[i].output != o) continue;
      ref.observations.push_back(i);
      ref.basis[0].push_back(1.0);
    }
    if (!ref.observations.empty()) data.references.push_back(std::move(ref));
  }
}

PointData table_point_data(const MeasurementTable& t, const Description& desc,
                           const BallbarFlags& circle, const std::vector<double>& parameters,
                           const std::function<void(const std::string&)>& warn) {
  if (is_line6d(t)) return line6d_point_data(t, desc, warn);
  if (is_ballbar_table(t)) {
    std::optional<BallbarCircle> c;
    PointData d = ballbar_point_data(t, desc, circle, parameters, c);
    std::vector<double> angles;
    for (const PointObservation& ob : d.observations)
      angles.push_back(t.column("angle_deg")[ob.row]);
    d.references.push_back(ballbar_centre_reference(d, angles));
    return d;
  }
  PointData d = point_data(t, desc);
  if (lower(trim(t.header_key("instrument"))) == "rtest") add_rtest_references(d);
  return d;
}

PointData merged_point_data(const std::vector<std::string>& files, const Description& desc,
                            const ReadOptions& ro,
                            const std::function<void(const std::string&)>& warn,
                            const BallbarFlags& circle, const std::vector<double>& parameters) {
  PointData all;
  for (const std::string& f : files) {
    // The header keys first (unknown columns allowed), to know the variant.
    ReadOptions probe;
    probe.allow_unknown = true;
    const bool line6d = is_line6d(read_measurements(f, probe));
    ReadOptions options = ro;
    if (line6d) {
      options = line6d_read_options();
      options.machine = ro.machine;
      options.allow_unknown = ro.allow_unknown;
    }
    const MeasurementTable t = read_measurements(f, options);
    if (warn)
      for (const auto& w : t.warnings) warn(w);
    all.append(table_point_data(t, desc, circle, parameters, warn));
  }
  return all;
}

}  // namespace weilgen
