// The exact numeric kinematic chain of a machine description: Eigen 4x4 products, exact
// rotation matrices (AngleAxis), exact inverses. Written independently of the generator: it is
// the reference the generated models are verified against (O(s^{r+1}) agreement) and the
// "straightforward numeric chain" the benchmarks compare with.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"

namespace weilgen {

class NumericChain {
 public:
  // Parameters take their defaults unless `set_parameters` is called.
  explicit NumericChain(Description desc);

  // Parameter values in the order of Description::parameters (mm / deg).
  void set_parameters(const std::vector<double>& values);

  // Tool frame (at the tool point) in the workpiece frame; for a machine with an `output`
  // transform, that transform (times Trans(point)) instead. `axes` in the joints' units, in
  // Description::axes() order; `errors` in base units (mm, rad), in Description::errors order.
  Eigen::Matrix4d tool_in_workpiece(const std::vector<double>& axes,
                                    const std::vector<double>& errors) const;

  // The workpiece frame in the base (machine) frame at zero errors; the identity for a machine
  // with an `output` transform (its outputs are in the base frame). What the workpiece frame's
  // outputs see of a displacement fixed in the machine: R^T times it.
  Eigen::Matrix4d workpiece_in_base(const std::vector<double>& axes) const;

  // (dx, dy, dz) in mm and the rotation vector (da, db, dc) in rad of the actual tool pose
  // relative to the nominal one, both in the workpiece frame (machines/README.md, "Outputs").
  std::array<double, 6> deviation(const std::vector<double>& axes,
                                  const std::vector<double>& errors) const;

  // The nominal tool frame at `axes` (tool_in_workpiece at zero errors): what deviation()
  // compares with. Many error vectors at one pose share it: deviation(axes, errors, nominal).
  Eigen::Matrix4d nominal(const std::vector<double>& axes) const;
  // deviation() with the pose's nominal frame given (nominal(axes)): the same numbers.
  std::array<double, 6> deviation(const std::vector<double>& axes,
                                  const std::vector<double>& errors,
                                  const Eigen::Matrix4d& nominal) const;

  // Forward steps of the deviation in one error at a time: `at` = deviation(axes, errors) and,
  // for every k with steps[k] != 0, stepped[k] = deviation(axes, errors with errors[k] +
  // steps[k]) (entries with steps[k] == 0 are left as they are; stepped is resized to
  // num_errors()). The same operations in the same order as those calls, hence the same numbers,
  // but a step recomputes only the transform of the body that holds the error and the products
  // after it in its branch (a serial machine; with linked coordinates or an output transform
  // every step is a whole deviation()). Finite-difference Jacobians of the exact chain.
  void deviation_steps(const std::vector<double>& axes, const std::vector<double>& errors,
                       const std::vector<double>& steps, const Eigen::Matrix4d& nominal,
                       std::array<double, 6>& at,
                       std::vector<std::array<double, 6>>& stepped) const;

  // d(nominal pose)/d(axes) at zero errors by central differences (step 1e-3 of the axis unit:
  // µm, millidegree; far above rounding, far below any curvature), 6 x num_axes: rows dx, dy, dz
  // in mm and the rotation rate da, db, dc in rad (the axial vector of dR·Rᵀ), per axis unit.
  Eigen::Matrix<double, 6, Eigen::Dynamic> nominal_jacobian(const std::vector<double>& axes) const;

  const Description& description() const { return desc_; }
  std::size_t num_axes() const { return axis_bodies_.size(); }
  std::size_t num_errors() const { return desc_.errors.size(); }

 private:
  // q_body: each body's joint value in its unit (0 for fixed bodies).
  Eigen::Matrix4d body_transform(int body, const std::vector<double>& q_body,
                                 const std::vector<double>& errors) const;
  Eigen::Matrix4d error_transform(int body, ErrorPlacement placement,
                                  const std::vector<double>& errors) const;
  // The frame of `point` (mm, in `body`'s frame) in the base frame: the bodies' transforms
  // from the base down to `body`, multiplied in that order.
  Eigen::Matrix4d branch(int body, const Eigen::Vector3d& point, const std::vector<double>& q_body,
                         const std::vector<double>& errors) const;
  Eigen::Vector3d point_of(const PointSpec& end) const;
  std::vector<double> body_values(const std::vector<double>& axes) const;  // q_body
  // The parameters' parts of the chain: each body's fixed offset and revolute axis point, the
  // tool and workpiece points (set_parameters recomputes them).
  void cache_parameters();
  // Parameters, independent coordinates (from `axes`) and linked coordinates by name.
  std::map<std::string, double> coordinate_values(const std::vector<double>& axes) const;
  // Chain points, derived quantities (by name, into `values`) and the output transform.
  Eigen::Matrix4d output_transform(std::map<std::string, double> values,
                                   const std::vector<double>& q_body,
                                   const std::vector<double>& errors) const;

  Description desc_;
  std::vector<int> axis_bodies_;
  std::vector<int> linked_bodies_;  // bodies with a linked joint
  std::map<std::string, double> params_;
  std::vector<std::vector<int>> paths_;                  // per body: chain_to(body)
  std::vector<std::array<std::vector<int>, 3>> placed_;  // per body and placement: its errors
  std::vector<Eigen::Matrix4d> offsets_;                 // per body: Trans(t) · its rotations
  std::vector<Eigen::Vector3d> through_;                 // per body: a revolute axis' point, mm
  Eigen::Vector3d tool_point_, workpiece_point_;         // mm, in their bodies' frames
};

}  // namespace weilgen
