#include "weilgen/analysis/axis_comp_table.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/linuxcnc.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace weilgen {

void AxisCompTableOptions::validate() const {
  if (axis.empty())
    throw std::invalid_argument("--comp-table needs --axis (the axis of the table)");
  if (points < 2 || points > kMaxCompEntries)
    throw std::invalid_argument("--comp-points " + std::to_string(points) + ": 2 to " +
                                std::to_string(kMaxCompEntries) + " (LinuxCNC's limit)");
  table.validate();
}

namespace {

struct Line {
  std::size_t axis = 0;  // index in Description::axes()
  PoseSet poses;         // the table's poses, along the axis
};

Line table_line(const Description& d, const AxisCompTableOptions& options) {
  options.validate();
  const std::vector<int> bodies = d.axes();
  Line line;
  line.axis = bodies.size();
  std::vector<std::string> names;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    names.push_back(d.bodies[static_cast<std::size_t>(bodies[i])].joint.coordinate);
    if (names.back() == options.axis) line.axis = i;
  }
  if (line.axis == bodies.size())
    throw std::invalid_argument("--axis " + options.axis + ": machine " + d.name +
                                " has the axes " + join(names));
  const Joint& joint = d.bodies[static_cast<std::size_t>(bodies[line.axis])].joint;
  if (!std::isfinite(joint.min) || !std::isfinite(joint.max) || !(joint.max > joint.min))
    throw std::invalid_argument("--axis " + options.axis +
                                ": the machine file gives the axis no finite range");
  // The line as a --grid: the axis over its range, the other axes as --comp-at says.
  const std::string grid = options.axis + "=" + format_number(joint.min) + ":" +
                           format_number(joint.max) + ":" + std::to_string(options.points) +
                           (options.at.empty() ? "" : "," + options.at);
  try {
    line.poses = parse_poses(d, {}, {grid});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("--comp-at " + options.at + ": " + e.what());
  }
  if (line.poses.grid_axes.size() != 1 || line.poses.grid_axes[0] != line.axis)
    throw std::invalid_argument("--comp-at " + options.at +
                                ": name the other axes once each, with one value (not " +
                                options.axis + ")");
  return line;
}

}  // namespace

void check_comp_table_flags(const std::string& path, const AxisCompTableOptions& options,
                            const std::vector<std::string>& given,
                            const std::vector<PathArg>& inputs, bool model_axis) {
  if (path.empty()) {
    if (!given.empty()) throw std::invalid_argument(given.front() + " needs --comp-table FILE");
    return;
  }
  if (model_axis)
    options.validate();
  else
    options.table.validate();
  check_output_paths(inputs, {{"--comp-table", path}});
}

void check_axis_comp_table(const Description& desc, const AxisCompTableOptions& options) {
  table_line(desc, options);
}

CompTable axis_comp_table(const Model& model, const ErrorParameterisation& param,
                          const std::vector<double>& theta, const AxisCompTableOptions& options) {
  const Description& d = model.description();
  const Line line = table_line(d, options);
  const std::size_t axis = line.axis;
  const PoseSet& poses = line.poses;
  // LinuxCNC's joint of the axis (the machine file's linuxcnc: section and defaults): the table
  // is in joint coordinates, the tool relative to the workpiece in the configuration's units.
  LinuxcncOverrides units;
  units.units = options.table.linear_unit;
  const LinuxcncJoint x = linuxcnc_mapping(d, units).axes[axis];
  NumericChain chain(d);
  chain.set_parameters(model.parameters());
  ModelData data(model);
  CompTable t;
  t.axis = options.axis + " (joint " + std::to_string(x.joint) + ", sign " +
           (x.sign < 0 ? "-1" : "+1") + ")";
  t.unit = x.unit;
  t.joint = x.joint;
  std::vector<double> errors(d.errors.size());
  for (const std::vector<double>& q : poses.poses) {
    param.errors_at(q.data(), theta.data(), errors.data());
    double out[6];
    model.deviation(data, q.data(), errors.data(), out);
    const auto j = chain.nominal_jacobian(q);
    const int row = x.rotary ? 3 : 0;  // orientation rows for a rotary axis, position rows else
    double dot = 0, norm2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double jk = j(row + k, static_cast<Eigen::Index>(axis));
      dot += jk * out[row + k];
      norm2 += jk * jk;
    }
    if (!(norm2 > 0))
      throw std::invalid_argument("--axis " + options.axis + ": at " + format_short(q[axis]) +
                                  " the axis moves nothing the table could correct");
    // The axis' deviation in its own unit (actual - commanded), then in joint coordinates.
    const double delta = dot / norm2;
    t.nominal.push_back(x.to_joint(q[axis]));
    t.forward.push_back(x.sign * delta / x.scale);
  }
  if (x.sign < 0) {  // LinuxCNC reads ascending joint positions
    std::reverse(t.nominal.begin(), t.nominal.end());
    std::reverse(t.forward.begin(), t.forward.end());
  }
  t.reverse = t.forward;
  t.validate();
  return t;
}

}  // namespace weilgen
