// The compensation part of a generated header: Compensate (docs/compensation.md), which inverts
// the model around the nominal kinematics (NominalPose, NominalJacobian) by a fixed-point
// iteration with a small dense least-squares solve.
#pragma once

#include <string>

namespace weilgen::gen {

// The C++ text of kCompensateOrientation, kCompensationLengthMm and both Compensate overloads.
// `weigh_orientation`: some axis turns the output frame (SymbolicModel::axes_turn_output), so
// the orientation rows take part in the least squares.
std::string compensation_code(bool weigh_orientation);

}  // namespace weilgen::gen
