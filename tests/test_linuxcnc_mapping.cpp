// LinuxCNC joints of a model (machine/linuxcnc.hpp, machines/README.md "LinuxCNC"): the defaults
// of every shipped machine against the nominal kinematics, the `linuxcnc:` section of a machine
// file, the flags' overrides, and every refusal with its position.
#include <doctest/doctest.h>

#include <cmath>

#include "test_support.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/machine/linuxcnc.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;

namespace {

const std::string kVmcHead = R"(weilgen: 1
name: lc
bodies:
  bed: {}
  y_axis: {parent: bed, joint: {type: prismatic, axis: y, coordinate: Y, range: [-400, 0]}, errors: {}}
  x_axis: {parent: y_axis, joint: {type: prismatic, axis: x, coordinate: X, range: [0, 500]}, errors: {}}
  table: {parent: x_axis}
  z_axis: {parent: bed, joint: {type: prismatic, axis: z, coordinate: Z, range: [-300, 0]}, errors: {}}
  c_axis: {parent: table, joint: {type: revolute, axis: z, coordinate: C, range: [-360, 360]}, errors: {}}
  work: {parent: c_axis}
tool: {body: z_axis}
workpiece: {body: work}
)";

}  // namespace

TEST_CASE("linuxcnc: the default signs of every shipped machine follow the nominal kinematics") {
  // LinuxCNC's axis letter L moves the tool relative to the workpiece along +L (ISO 841); the
  // model's nominal Jacobian at the home pose says which way the model's axis moves it. The
  // default sign must be the sign of that entry wherever the axis moves along its letter.
  for (const std::string name :
       {"vmc_3axis", "five_axis_ac", "gantry_grinder", "head_head_bc", "two_axis", "pipe_cutter"}) {
    CAPTURE(name);
    const Description d = load_machine_file(test::machine_path(name));
    const LinuxcncMapping m = linuxcnc_mapping(d);
    REQUIRE(m.axes.size() == d.axes().size());
    CHECK(m.num_joints == static_cast<int>(m.axes.size()));
    CHECK(m.coordinates.size() == m.axes.size());
    if (d.output) continue;  // the pipe cutter: an output transform, no workpiece branch
    NumericChain chain(d);
    std::vector<double> home;
    for (int b : d.axes()) {
      const Joint& j = d.bodies[static_cast<std::size_t>(b)].joint;
      home.push_back(j.type == JointType::Revolute ? 0.0 : 0.5 * (j.min + j.max));
    }
    const auto jac = chain.nominal_jacobian(home);
    for (const LinuxcncJoint& x : m.axes) {
      CAPTURE(x.coordinate);
      const std::string letters = "XYZABCUVW";
      const auto at = letters.find(x.letter);
      const int row = static_cast<int>(at % 3) + (x.rotary ? 3 : 0);
      const double entry = jac(row, static_cast<Eigen::Index>(x.axis));
      // the entry is +-1 (mm per mm, rad per rad) for an axis along its letter at home
      const double unit = x.rotary ? kPi / 180 : 1.0;
      if (std::fabs(std::fabs(entry) - unit) < 1e-9) CHECK(x.sign == (entry > 0 ? 1 : -1));
    }
  }
  const LinuxcncMapping vmc = linuxcnc_mapping(load_machine_file(test::machine_path("vmc_3axis")));
  // kAxes order Y, X, Z; trivkins XYZ: X joint 0, Y joint 1, Z joint 2; X and Y carry the table.
  CHECK(vmc.coordinates == "XYZ");
  CHECK(vmc.axes[0].coordinate == "Y");
  CHECK(vmc.axes[0].joint == 1);
  CHECK(vmc.axes[0].sign == -1);
  CHECK(vmc.axes[1].joint == 0);
  CHECK(vmc.axes[1].sign == -1);
  CHECK(vmc.axes[2].joint == 2);
  CHECK(vmc.axes[2].sign == 1);
  CHECK(vmc.axes[1].sign_reason == "carries the workpiece");
  const LinuxcncMapping five =
      linuxcnc_mapping(load_machine_file(test::machine_path("five_axis_ac")));
  // kAxes X, Z, Y, A, C; coordinates=XYZAC: C is joint 4 (the old .hal said joint.5).
  CHECK(five.coordinates == "XYZAC");
  CHECK(five.axes[4].coordinate == "C");
  CHECK(five.axes[4].joint == 4);
  CHECK(five.axes[3].joint == 3);
  CHECK(five.axes[1].joint == 2);
  CHECK((five.axes[0].sign == 1 && five.axes[1].sign == 1));
  CHECK((five.axes[2].sign == -1 && five.axes[3].sign == -1 && five.axes[4].sign == -1));
  // The pipe cutter's coordinates are not letters: X, Y231 -> Y, A04 -> A, Y451 -> U, Z453 -> Z.
  const LinuxcncMapping pipe =
      linuxcnc_mapping(load_machine_file(test::machine_path("pipe_cutter")));
  CHECK(pipe.coordinates == "XYZAU");
}

TEST_CASE("linuxcnc: the machine file's section and the flags override signs, offsets, units") {
  const Description plain = load_machine_text(kVmcHead, "lc.yaml");
  LinuxcncMapping m = linuxcnc_mapping(plain);
  CHECK(m.coordinates == "XYZC");
  CHECK(m.axes[3].sign == -1);  // C turns the workpiece
  const Description d = load_machine_text(kVmcHead + R"(linuxcnc:
  units: inch
  axes:
    X: {sign: 1, offset: 250}
    C: {offset: 90, joint: 0}
    Z: {letter: W}
)",
                                          "lc.yaml");
  m = linuxcnc_mapping(d);
  // Joints: C as written (0), then the others in trivkins order X, Y, W.
  CHECK(m.coordinates == "CXYW");
  const LinuxcncJoint& x = m.axes[1];
  CHECK(x.coordinate == "X");
  CHECK(x.sign == 1);
  CHECK(x.sign_reason == "machine file");
  CHECK(x.offset == 250);
  CHECK(x.scale == doctest::Approx(25.4));
  CHECK(x.unit == "inch");
  CHECK(x.to_model(2.0) == doctest::Approx(250 + 50.8));
  CHECK(x.to_joint(x.to_model(-3.5)) == doctest::Approx(-3.5));
  const LinuxcncJoint& c = m.axes[3];
  CHECK(c.joint == 0);
  CHECK(c.scale == 1.0);  // deg to deg
  CHECK(c.unit == "deg");
  CHECK(c.to_model(10) == doctest::Approx(80));  // 90 - 10
  CHECK(m.axes[2].letter == 'W');

  LinuxcncOverrides o;
  o.units = "mm";
  o.signs = parse_linuxcnc_signs(d, "X=-1, C=1");
  o.offsets = parse_linuxcnc_offsets(d, "Y=-0.2m,C=0.5rad");
  m = linuxcnc_mapping(d, o);
  CHECK(m.axes[1].sign == -1);
  CHECK(m.axes[1].sign_reason == "--sign");
  CHECK(m.axes[1].scale == 1.0);
  CHECK(m.axes[0].offset == doctest::Approx(-200));
  CHECK(m.axes[3].offset == doctest::Approx(0.5 * 180 / kPi));
  CHECK(m.axes[3].sign == 1);

  const auto flag_error = [&](auto parse, const std::string& text) {
    try {
      parse(d, text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  CHECK(flag_error(parse_linuxcnc_signs, "X=2").find("--sign X=2: a sign is 1 or -1") == 0);
  CHECK(flag_error(parse_linuxcnc_signs, "Q=1").find("--sign \"Q=1\": 'Q' is not an axis") == 0);
  CHECK(flag_error(parse_linuxcnc_signs, "X").find("expected AXIS=VALUE") != std::string::npos);
  CHECK(flag_error(parse_linuxcnc_signs, "X=1,X=-1").find("axis X given twice") !=
        std::string::npos);
  CHECK(flag_error(parse_linuxcnc_offsets, "C=3mm").find("C is in deg, not mm") !=
        std::string::npos);
  CHECK(flag_error(parse_linuxcnc_offsets, "X=abc").find("--offset X") == 0);
}

TEST_CASE("linuxcnc: a bad section is refused at its position") {
  const auto error_of = [](const std::string& tail) {
    return test::load_error(kVmcHead + tail, "lc.yaml");
  };
  CHECK(error_of("linuxcnc: {units: cm}\n").find("lc.yaml:13:19: ") == 0);
  CHECK(error_of("linuxcnc: {units: cm}\n").find("mm or inch") != std::string::npos);
  CHECK(error_of("linuxcnc: {kins: trivkins}\n").find("lc.yaml:13:12") == 0);
  CHECK(error_of("linuxcnc: {axes: {Q: {sign: 1}}}\n").find("lc.yaml:13:19: ") == 0);
  CHECK(error_of("linuxcnc: {axes: {Q: {sign: 1}}}\n").find("'Q' is not an axis of the model") !=
        std::string::npos);
  CHECK(error_of("linuxcnc: {axes: {X: {sign: 2}}}\n").find("sign must be 1 or -1") !=
        std::string::npos);
  CHECK(error_of("linuxcnc: {axes: {X: {letter: Q}}}\n").find("letter must be one of") !=
        std::string::npos);
  CHECK(error_of("linuxcnc: {axes: {X: {joint: 1.5}}}\n").find("joint must be a whole number") !=
        std::string::npos);
  CHECK(error_of("linuxcnc: {axes: {X: {offset: 1, size: 2}}}\n")
            .find("lc.yaml:13:34: linuxcnc.axes.X: unknown key") == 0);
  // Whole-section checks name the axis that clashes.
  const std::string twice = error_of("linuxcnc:\n  axes:\n    X: {letter: Y}\n");
  CHECK(twice.find("lc.yaml:") == 0);
  CHECK(twice.find("two axes have the letter Y") != std::string::npos);
  const std::string joints = error_of("linuxcnc:\n  axes:\n    X: {joint: 1}\n    Z: {joint: 1}\n");
  CHECK(joints.find("lc.yaml:16:5: linuxcnc: joint 1 is given to two axes") == 0);
  const std::string gap = error_of("linuxcnc:\n  axes:\n    X: {joint: 7}\n");
  CHECK(gap.find("joint numbers must be 0 ... 3 without gaps") != std::string::npos);
}
