// Machine description loading: expressions, ISO 230-1 names, a good machine, and one test per kind
// of bad input (each asserting the exact file:line:column of the node at fault).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "weilgen/base/expr.hpp"
#include "weilgen/machine/iso_names.hpp"
#include "weilgen/machine/yaml_loader.hpp"

using namespace weilgen;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string load_error(const std::string& yaml) {
  const std::string m = test::load_error(yaml);
  return m.empty() ? "(loaded without error)" : m;
}

// The load fails at `where` ("bad.yaml:line:column") with a message containing every word.
void expect_error(const std::string& yaml, const std::string& where,
                  const std::vector<std::string>& words) {
  const std::string message = load_error(yaml);
  INFO("message: " << message);
  CHECK(message.rfind(where + ": ", 0) == 0);
  for (const std::string& w : words) {
    INFO("expected word: " << w);
    CHECK(message.find(w) != std::string::npos);
  }
}

std::string expr_error(const std::string& text) {
  try {
    parse_expr(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(parsed)";
}

Joint make_joint(JointType type, Vec3 axis, const std::string& coordinate) {
  Joint j;
  j.type = type;
  j.axis = axis;
  j.coordinate = coordinate;
  return j;
}

}  // namespace

// ---- Expressions ----------------------------------------------------------------------------

TEST_CASE("expr: parses, evaluates and prints") {
  const std::map<std::string, double> values = {{"L04", 10}, {"L23", 3}, {"tool_length", 150}};
  CHECK(parse_expr("L04 - L23").str() == "L04 - L23");
  CHECK(parse_expr("L04 - L23").eval(values) == 7);
  CHECK(parse_expr("-tool_length").str() == "-tool_length");
  CHECK(parse_expr("-tool_length").eval(values) == -150);
  CHECK(parse_expr("0.05/6").eval({}) == doctest::Approx(0.05 / 6));
  CHECK(parse_expr("1e-3").eval({}) == 1e-3);
  CHECK(parse_expr("2.5E+2").eval({}) == 250);
  CHECK(parse_expr("2*pi").eval({}) == doctest::Approx(2 * kPi));
  CHECK(parse_expr("2*pi").str() == "2*pi");
  CHECK(parse_expr("2^3^2").eval({}) == 512);
  CHECK(parse_expr("-2^2").eval({}) == -4);
  CHECK(parse_expr("(1 + 2)*3").eval({}) == 9);
  CHECK(parse_expr("(1 + 2)*3").str() == "(1 + 2)*3");
  CHECK(parse_expr("a - (b - c)").str() == "a - (b - c)");
  CHECK(parse_expr("-(a + b)").str() == "-(a + b)");
  CHECK(parse_expr("-(-(-a))").str() == "---a");  // not "-(-(-a))": twice as deep to read back
  CHECK(parse_expr("-(-a^2)").str() == "--a^2");
  CHECK(parse_expr("--a^2").eval({{"a", 3}}) == 9);
  CHECK(parse_expr("-(-a*b)").str() == "-(-a*b)");
  // 150 signs read back from their printed form (the parser allows 200 levels).
  const Expr signs = parse_expr(std::string(150, '-') + "a");
  CHECK(parse_expr(signs.str()).eval({{"a", 2}}) == 2);
  CHECK(parse_expr("1 - -2").eval({}) == 3);
  CHECK(parse_expr("-5").is_number());
  CHECK(parse_expr("-5").number == -5);
  CHECK(parse_expr("b*a + a/c").params() == std::vector<std::string>{"a", "b", "c"});
  CHECK(parse_expr("pi").params().empty());
}

TEST_CASE("expr: errors name the position") {
  CHECK(expr_error("").find("empty") != std::string::npos);
  CHECK(expr_error("1 +").find("position 4") != std::string::npos);
  CHECK(expr_error("(1 + 2").find("expected ')'") != std::string::npos);
  CHECK(expr_error("a $ b").find("unexpected '$' at position 3") != std::string::npos);
  CHECK(expr_error("2 3").find("unexpected '3' at position 3") != std::string::npos);
  CHECK_THROWS_AS(parse_expr("L1 + 1").eval({}), std::out_of_range);
}

// ---- ISO 230-1 names ------------------------------------------------------------------------

TEST_CASE("iso names: prismatic and revolute joints") {
  const Joint x = make_joint(JointType::Prismatic, {1, 0, 0}, "X");
  const Joint c = make_joint(JointType::Revolute, {0, 0, 1}, "C");
  const IsoMatch e_yx = match_iso_name(x, "E_YX");
  REQUIRE(e_yx.status == IsoMatch::Status::Fits);
  CHECK(e_yx.error.group == "straightness");
  CHECK(e_yx.error.direction == Vec3{0, 1, 0});
  CHECK(e_yx.error.unit == "um");
  CHECK(match_iso_name(c, "E_CC").error.group == "positioning");
  CHECK(match_iso_name(c, "E_AC").error.group == "tilt");
  CHECK(match_iso_name(c, "E_ZC").error.group == "axial");
  CHECK(match_iso_name(c, "E_XC").error.group == "radial");
  CHECK(match_iso_name(c, "E_Z0C").error.placement == ErrorPlacement::Before);
  CHECK(match_iso_name(c, "E_A0C").error.group == "squareness");
  CHECK(match_iso_name(x, "E_A0X").status == IsoMatch::Status::Mismatch);
  CHECK(match_iso_name(x, "E_Y0X").status == IsoMatch::Status::Mismatch);
  CHECK(match_iso_name(x, "E_XY").status == IsoMatch::Status::Mismatch);
  CHECK(match_iso_name(x, "ball_screw").status == IsoMatch::Status::NotIso);
  // Directions are body-frame axes whatever the sign of the joint axis.
  const Joint minus_y = make_joint(JointType::Prismatic, {0, -1, 0}, "Y");
  CHECK(match_iso_name(minus_y, "E_YY").error.group == "positioning");
  CHECK(match_iso_name(minus_y, "E_YY").error.direction == Vec3{0, 1, 0});
  CHECK(iso_motion_errors(minus_y) ==
        std::vector<std::string>{"E_XY", "E_YY", "E_ZY", "E_AY", "E_BY", "E_CY"});
  const Joint skewed = make_joint(JointType::Prismatic, {0.6, 0.8, 0}, "U");
  CHECK(match_iso_name(skewed, "E_XU").status == IsoMatch::Status::Mismatch);
  CHECK_THROWS_AS(iso_motion_errors(skewed), std::invalid_argument);
}

// ---- A good machine -------------------------------------------------------------------------

namespace {

// Bodies out of tree order on purpose (table before its parent).
const char* const kGoodMachine = R"(weilgen: 1
name: mini
title: Mini machine
notes: test
parameters:
  tool_length: {value: 150, unit: mm, description: gauge line to tool tip}
  L01: 120
  tilt: {value: 90, unit: deg}
groups: [thermal, spindle]
error_defaults:
  positioning: {sigma: 5, unit: um}
  straightness: {sigma: 0.002, unit: mm}
  angular: {uniform: [-5, 5], unit: urad}
bodies:
  table:
    parent: x_carriage
  bed: {}
  x_carriage:
    parent: bed
    offset: {translation: [0, 0, L01], rotation: [{axis: z, angle: tilt}]}
    joint: {type: prismatic, axis: x, coordinate: X, unit: mm, range: [0, 1000]}
    errors:
      E_XX: {aliases: [δxx], sigma: 0.05/6, unit: mm}
      E_YX: {}
      E_BX: {aliases: [{name: Sxz, sign: -1}]}
  y_slide:
    parent: bed
    joint: {type: prismatic, axis: y, coordinate: Y, unit: um}
    errors:
      E_C0Y: {sigma: 3, unit: arcsec}
  c_table:
    parent: y_slide
    joint: {type: revolute, axis: z, coordinate: C, range: [-180, 180]}
    errors:
      E_X0C: {sigma: 1}
      E_C0C: {normal: [0.5, 2]}
      E_Z0C: {truncnormal: [0, 1, -2, 2], unit: nm}
      pitch: {effect: translation, direction: [0, 0, 2], group: spindle, sigma: 2}
  z_ram:
    parent: bed
    joint: {type: prismatic, axis: z, coordinate: Z}
  tool:
    parent: c_table
tool: {body: tool, point: [0, 0, -tool_length]}
workpiece: {body: table}
algebra:
  order: 2
  relations:
    - squares: all
    - within: [angular]
    - between: [angular, squareness]
    - pair: [δxx, Sxz]
    - monomial: [E_XX, E_XX, E_C0Y]
)";

}  // namespace

TEST_CASE("loader: a good machine") {
  const Description d = load_machine_text(kGoodMachine, "mini.yaml");
  CHECK(d.name == "mini");
  CHECK(d.title == "Mini machine");
  CHECK(d.source_file == "mini.yaml");
  CHECK(d.groups.back() == "spindle");
  REQUIRE(d.parameters.size() == 3);
  CHECK(d.parameter_defaults().at("tool_length") == 150);
  CHECK(d.parameters[2].unit == "deg");

  // Base first, parents before children, otherwise file order.
  std::vector<std::string> order;
  for (const Body& b : d.bodies) order.push_back(b.name);
  CHECK(order == std::vector<std::string>{"bed", "x_carriage", "y_slide", "c_table", "z_ram",
                                          "tool", "table"});
  CHECK(d.bodies[0].parent == -1);
  CHECK(d.bodies[6].parent == d.body_index("x_carriage"));
  CHECK(d.chain_to(d.body_index("tool")) == std::vector<int>{0, d.body_index("y_slide"),
                                                             d.body_index("c_table"),
                                                             d.body_index("tool")});
  CHECK(d.axes() == std::vector<int>{1, 2, 3, 4});
  CHECK(d.bodies[d.tool.body].name == "tool");
  CHECK(d.bodies[d.workpiece.body].name == "table");
  CHECK(d.tool.point[2].str() == "-tool_length");

  const Body& x = d.bodies[1];
  CHECK(x.joint.to_base == 1);
  CHECK(x.joint.max == 1000);
  CHECK_FALSE(x.offset.is_identity());
  CHECK(x.offset.translation[2].str() == "L01");
  CHECK(x.offset.rotations.at(0).angle_deg.str() == "tilt");
  CHECK(d.bodies[0].offset.is_identity());
  CHECK(d.bodies[2].joint.to_base == 1e-3);
  CHECK(d.bodies[3].joint.unit == "deg");
  CHECK(d.bodies[3].joint.to_base == doctest::Approx(kPi / 180));

  // Errors in body order, each body's in listed order.
  std::vector<std::string> names;
  for (const ErrorDef& e : d.errors) names.push_back(e.name);
  CHECK(names == std::vector<std::string>{"E_XX", "E_YX", "E_BX", "E_C0Y", "E_X0C", "E_C0C",
                                          "E_Z0C", "pitch", "E_XZ", "E_YZ", "E_ZZ", "E_AZ", "E_BZ",
                                          "E_CZ"});
  CHECK(x.errors == std::vector<int>{0, 1, 2});
  CHECK(d.errors[4].body == 3);

  const ErrorDef& exx = d.errors[d.error_index("δxx")];
  CHECK(exx.name == "E_XX");
  CHECK(exx.iso == "E_XX");
  CHECK(exx.group == "positioning");
  CHECK(exx.placement == ErrorPlacement::After);
  CHECK(exx.dependence == Dependence::PDGE);
  CHECK(exx.direction == Vec3{1, 0, 0});
  CHECK(exx.unit == "mm");
  CHECK(exx.distribution.kind == Distribution::Kind::Normal);
  CHECK(exx.distribution.b == doctest::Approx(0.05 / 6));

  const ErrorDef& eyx = d.errors[1];
  CHECK(eyx.group == "straightness");
  CHECK(eyx.direction == Vec3{0, 1, 0});
  CHECK(eyx.effect == ErrorEffect::Translation);
  CHECK(eyx.unit == "mm");  // from error_defaults
  CHECK(eyx.distribution.b == 0.002);

  const ErrorDef& ebx = d.errors[d.error_index("Sxz")];
  CHECK(ebx.name == "E_BX");
  CHECK(ebx.aliases.at(0).sign == -1);
  CHECK(ebx.group == "angular");
  CHECK(ebx.effect == ErrorEffect::Rotation);
  CHECK(ebx.direction == Vec3{0, 1, 0});
  CHECK(ebx.unit == "urad");
  CHECK(ebx.to_base == 1e-6);
  CHECK(ebx.distribution.str() == "uniform(-5, 5)");

  const ErrorDef& ec0y = d.errors[3];
  CHECK(ec0y.group == "squareness");
  CHECK(ec0y.placement == ErrorPlacement::Axis);
  CHECK(ec0y.dependence == Dependence::PIGE);
  CHECK(ec0y.effect == ErrorEffect::Rotation);
  CHECK(ec0y.direction == Vec3{0, 0, 1});
  CHECK(ec0y.to_base == doctest::Approx(kPi / 648000));

  const ErrorDef& ex0c = d.errors[4];
  CHECK(ex0c.group == "location");
  CHECK(ex0c.placement == ErrorPlacement::Axis);
  CHECK(ex0c.dependence == Dependence::PIGE);
  CHECK(ex0c.direction == Vec3{1, 0, 0});
  CHECK(ex0c.unit == "um");
  CHECK(ex0c.to_base == 1e-3);

  const ErrorDef& ec0c = d.errors[5];
  CHECK(ec0c.group == "location");
  CHECK(ec0c.placement == ErrorPlacement::Before);
  CHECK(ec0c.effect == ErrorEffect::Rotation);
  CHECK(ec0c.direction == Vec3{0, 0, 1});
  CHECK(ec0c.distribution.str() == "normal(0.5, 2)");

  const ErrorDef& ez0c = d.errors[6];
  CHECK(ez0c.placement == ErrorPlacement::Before);
  CHECK(ez0c.to_base == 1e-6);
  CHECK(ez0c.distribution.str() == "truncnormal(0, 1, -2, 2)");

  const ErrorDef& pitch = d.errors[7];
  CHECK(pitch.iso.empty());
  CHECK(pitch.group == "spindle");
  CHECK(pitch.direction == Vec3{0, 0, 1});
  CHECK(pitch.placement == ErrorPlacement::After);
  CHECK(pitch.dependence == Dependence::PDGE);
  CHECK(pitch.unit == "um");

  // Implicit ISO expansion of z_ram, fixed X Y Z A B C order, defaults converted.
  const ErrorDef& ezz = d.errors[10];
  CHECK(ezz.name == "E_ZZ");
  CHECK(ezz.group == "positioning");
  CHECK(ezz.unit == "um");
  CHECK(ezz.distribution.b == 5);
  CHECK(d.errors[8].distribution.b == 0.002);

  REQUIRE(d.algebra.relations.size() == 5);
  CHECK(d.algebra.order == 2);
  CHECK(d.algebra.relations[0].kind == Relation::Kind::Squares);
  CHECK(d.algebra.relations[0].names.empty());
  CHECK(d.algebra.relations[3].names == std::vector<std::string>{"E_XX", "E_BX"});
  CHECK(d.algebra.relations[4].names.size() == 3);
}

TEST_CASE("loader: error_defaults values follow the error's own unit") {
  const Description d = load_machine_text(R"(weilgen: 1
name: m
error_defaults:
  positioning: {sigma: 5, unit: um}
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors: {E_XX: {unit: mm}}
tool: {body: x}
workpiece: {body: bed}
)",
                                          "m.yaml");
  CHECK(d.errors.at(0).unit == "mm");
  CHECK(d.errors.at(0).distribution.b == doctest::Approx(0.005));
}

// A rotary table whose location group holds a length (E_X0C) and an angle (E_C0C).
std::string location_machine(const std::string& location_default) {
  return "weilgen: 1\nname: m\nerror_defaults:\n  location: " + location_default +
         "\n  radial: {sigma: 1, unit: um}\n  axial: {sigma: 1, unit: um}\n"
         "  positioning: {sigma: 5, unit: urad}\n  tilt: {sigma: 5, unit: urad}\n"
         "bodies:\n  bed: {}\n  table:\n    parent: bed\n"
         "    joint: {type: revolute, axis: z, coordinate: C, range: [-360, 360]}\n"
         "    errors:\n      E_X0C: {}\n      E_C0C: {}\n      E_CC: {}\n"
         "tool: {body: bed}\nworkpiece: {body: table}\n";
}

TEST_CASE("loader: error_defaults per kind: a group that mixes lengths and angles") {
  const Description d =
      load_machine_text(location_machine("\n    translation: {sigma: 4, unit: um}\n"
                                         "    rotation: {uniform: [-10, 10], unit: µrad}"),
                        "m.yaml");
  const ErrorDef& x0c = d.errors.at(static_cast<std::size_t>(d.error_index("E_X0C")));
  const ErrorDef& c0c = d.errors.at(static_cast<std::size_t>(d.error_index("E_C0C")));
  CHECK(x0c.group == "location");
  CHECK(c0c.group == "location");
  CHECK(x0c.unit == "um");
  CHECK(x0c.distribution.kind == Distribution::Kind::Normal);
  CHECK(x0c.distribution.b == 4);
  CHECK(x0c.to_base == doctest::Approx(1e-3));
  CHECK(c0c.unit == "urad");  // the one unit table's spelling of µrad
  CHECK(c0c.distribution.kind == Distribution::Kind::Uniform);
  CHECK(c0c.distribution.hi == 10);
  CHECK(c0c.to_base == doctest::Approx(1e-6));
  // A group distribution and one kind's override: the translation takes the group's.
  const Description e = load_machine_text(
      location_machine("{sigma: 0.002, unit: mm, rotation: {sigma: 3, unit: arcsec}}"), "m.yaml");
  const ErrorDef& ex = e.errors.at(static_cast<std::size_t>(e.error_index("E_X0C")));
  const ErrorDef& ec = e.errors.at(static_cast<std::size_t>(e.error_index("E_C0C")));
  CHECK(ex.unit == "mm");
  CHECK(ex.distribution.b == 0.002);
  CHECK(ec.unit == "arcsec");
  CHECK(ec.distribution.b == 3);
  CHECK(ec.to_base == doctest::Approx(kPi / 180 / 3600));
}

TEST_CASE("bad: error_defaults per kind") {
  // One unit for the whole group: the angle E_C0C cannot take µm (names the error and its line).
  expect_error(location_machine("{sigma: 5, unit: µm}"), "bad.yaml:4:30",
               {"unit 'µm' is a length but error 'E_C0C' (line 16) is a rotation",
                "location: {translation: {..., unit: um}, rotation: {..., unit: urad}}"});
  // A kind's unit of the other dimension, at the unit.
  expect_error(location_machine("{translation: {sigma: 5, unit: urad}, rotation: {sigma: 5}}"),
               "bad.yaml:4:44",
               {"error_defaults.location.translation.unit",
                "unit 'urad' is an angle but a translation default needs a length"});
  // A kind without a distribution; an unknown key in a kind; a unit beside kinds only.
  expect_error(location_machine("{translation: {unit: um}, rotation: {sigma: 5}}"), "bad.yaml:4:27",
               {"error_defaults.location.translation", "give a distribution"});
  expect_error(location_machine("{translation: {sigma: 1, mean: 0}, rotation: {sigma: 5}}"),
               "bad.yaml:4:38", {"unknown key 'mean'"});
  expect_error(location_machine("{unit: um, translation: {sigma: 1}, rotation: {sigma: 5}}"),
               "bad.yaml:4:20", {"'unit' goes with a distribution"});
  // Only translations given: the rotation E_C0C has no default (at the error, naming the kind).
  expect_error(location_machine("{translation: {sigma: 5, unit: um}}"), "bad.yaml:16:7",
               {"'E_C0C' has no distribution", "error_defaults.location has none for a rotation",
                "add rotation: {...}"});
  // Both kinds given: the group's own distribution would apply to nothing.
  expect_error(location_machine("{sigma: 1, translation: {sigma: 1}, rotation: {sigma: 5}}"),
               "bad.yaml:4:13", {"applies to no error"});
}

TEST_CASE("loader: the one unit table: µm and µrad (micro sign or Greek mu) read as um and urad") {
  // The same machine written with um/urad and with µm (U+00B5), μm (U+03BC) and µrad: the same
  // description, the units stored in their ASCII spelling.
  const auto machine = [](const std::string& length, const std::string& angle) {
    return "weilgen: 1\nname: m\nerror_defaults:\n  angular: {sigma: 2, unit: " + angle +
           "}\nbodies:\n  bed: {}\n  x:\n    parent: bed\n"
           "    joint: {type: prismatic, axis: x, coordinate: X, unit: " +
           length + "}\n    errors: {E_XX: {sigma: 5, unit: " + length +
           "}, E_AX: {unit: " + angle + "}}\ntool: {body: x}\nworkpiece: {body: bed}\n";
  };
  const Description ascii = load_machine_text(machine("um", "urad"), "a.yaml");
  for (const auto& units : std::vector<std::pair<std::string, std::string>>{
           {"\u00b5m", "\u00b5rad"}, {"\u03bcm", "\u03bcrad"}}) {
    const std::string& length = units.first;  // clang < 16 cannot capture a structured binding
    const std::string& angle = units.second;
    CAPTURE(length);
    const Description d = load_machine_text(machine(length, angle), "b.yaml");
    REQUIRE(d.errors.size() == 2);
    for (std::size_t i = 0; i < 2; ++i) {
      CHECK(d.errors[i].unit == ascii.errors[i].unit);
      CHECK(d.errors[i].to_base == ascii.errors[i].to_base);
      CHECK(d.errors[i].distribution.b == ascii.errors[i].distribution.b);
    }
    CHECK(d.errors[0].unit == "um");
    CHECK(d.errors[0].to_base == 1e-3);
    CHECK(d.errors[1].unit == "urad");
    CHECK(d.errors[1].to_base == 1e-6);
    const Joint& j = d.bodies[static_cast<std::size_t>(d.coordinate_body("X"))].joint;
    CHECK(j.unit == "um");
    CHECK(j.to_base == 1e-3);
  }
  // Dimension checks apply to the micro spellings too: a length unit on a rotation, named as
  // written.
  const std::string bad = machine("um", "urad");
  std::string wrong = bad;
  wrong.replace(wrong.find("E_AX: {unit: urad}"), 18, "E_AX: {unit: \u00b5m}");
  expect_error(wrong, "bad.yaml:10:55",
               {"bodies.x.errors.E_AX.unit", "unit '\u00b5m' is a length", "'E_AX' is a rotation"});
}

TEST_CASE("loader: shipped machines load and resolve by name") {
  namespace fs = std::filesystem;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(WEILGEN_MACHINES_DIR)) {
    if (entry.path().extension() != ".yaml") continue;
    INFO(entry.path().string());
    const std::string resolved = resolve_machine(entry.path().stem().string());
    CHECK(fs::equivalent(resolved, entry.path()));
    CHECK_NOTHROW(load_machine_file(resolved));
    ++count;
  }
  CHECK(count > 0);
}

TEST_CASE("loader: resolve_machine names the missing machine") {
  try {
    resolve_machine("no_such_machine");
    FAIL("resolve_machine accepted a missing machine");
  } catch (const InputError& e) {
    CHECK(e.loc().file == "no_such_machine");
    CHECK(std::string(e.what()).find("no shipped machine") != std::string::npos);
  }
  CHECK_THROWS_AS(load_machine_file("/nonexistent/m.yaml"), InputError);
}

// ---- Bad input: one test per kind ------------------------------------------------------------

TEST_CASE("bad: YAML syntax error") {
  expect_error("weilgen: 1\nname: bad\nbodies: {bed: {}\ntool: x\n", "bad.yaml:4:1",
               {"YAML syntax error", "end of map flow"});
}

TEST_CASE("bad: unknown top-level key") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
tool: {body: bed}
workpiece: {body: bed}
colour: red
)",
               "bad.yaml:7:1", {"unknown key 'colour'", "allowed:", "workpiece"});
}

TEST_CASE("bad: unknown key in a body") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    colour: red
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:7:5",
               {"bodies.x", "unknown key 'colour'", "parent, offset, joint, errors"});
}

TEST_CASE("bad: unknown key in a joint") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X, speed: 3}
    errors: none
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:7:54", {"bodies.x.joint", "unknown key 'speed'"});
}

TEST_CASE("bad: unknown key in an error") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors:
      E_XX: {sigma: 1, colour: red}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:9:24", {"bodies.x.errors.E_XX", "unknown key 'colour'", "sigma"});
}

TEST_CASE("bad: unknown key in offset, parameter, tool, algebra, error_defaults") {
  const std::string head = "weilgen: 1\nname: bad\n";
  const std::string bodies = "bodies:\n  bed: {}\n";
  const std::string ends = "tool: {body: bed}\nworkpiece: {body: bed}\n";
  expect_error(head + "parameters:\n  L: {value: 1, size: 2}\n" + bodies + ends, "bad.yaml:4:17",
               {"parameters.L", "unknown key 'size'"});
  expect_error(head + bodies + "  x: {parent: bed, offset: {shift: 1}}\n" + ends, "bad.yaml:5:29",
               {"bodies.x.offset", "unknown key 'shift'"});
  expect_error(head + bodies + "tool: {body: bed, tip: 1}\nworkpiece: {body: bed}\n",
               "bad.yaml:5:19", {"tool", "unknown key 'tip'"});
  expect_error(head + bodies + ends + "algebra: {order: 1, ring: x}\n", "bad.yaml:7:21",
               {"algebra", "unknown key 'ring'"});
  expect_error(head + "error_defaults:\n  angular: {sigma: 1, mean: 0}\n" + bodies + ends,
               "bad.yaml:4:23", {"error_defaults.angular", "unknown key 'mean'"});
}

TEST_CASE("bad: missing required keys") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
workpiece: {body: bed}
)",
               "bad.yaml:1:1", {"missing required key 'tool'"});
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:7:12", {"bodies.x.joint", "missing required key 'coordinate'"});
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
tool:
workpiece: {body: bed}
)",
               "bad.yaml:5:1", {"tool", "missing required key 'body'"});
}

TEST_CASE("bad: format version") {
  expect_error(
      "weilgen: 2\nname: bad\nbodies: {bed: {}}\ntool: {body: bed}\n"
      "workpiece: {body: bed}\n",
      "bad.yaml:1:10", {"weilgen", "unsupported format version '2'"});
}

TEST_CASE("bad: names that are not identifiers") {
  const std::string ends = "tool: {body: bed}\nworkpiece: {body: bed}\n";
  expect_error("weilgen: 1\nname: my machine\nbodies: {bed: {}}\n" + ends, "bad.yaml:2:7",
               {"name", "'my machine' is not an identifier"});
  expect_error("weilgen: 1\nname: m\nbodies: {bed: {}, 2x: {parent: bed}}\n" + ends,
               "bad.yaml:3:19", {"bodies", "body name '2x' is not an identifier"});
  expect_error(
      "weilgen: 1\nname: m\nbodies:\n  bed: {}\n"
      "  x: {parent: bed, joint: {type: prismatic, axis: x, coordinate: X-1}}\n" +
          ends,
      "bad.yaml:5:66", {"bodies.x.joint.coordinate", "'X-1' is not an identifier"});
  expect_error("weilgen: 1\nname: m\nparameters: {tool length: 3}\nbodies: {bed: {}}\n" + ends,
               "bad.yaml:3:14", {"parameters", "'tool length' is not an identifier"});
  expect_error("weilgen: 1\nname: m\nbodies:\n  bed:\n    errors:\n      bad-name: {}\n" + ends,
               "bad.yaml:6:7", {"bodies.bed.errors", "'bad-name' is not an identifier"});
}

TEST_CASE("bad: duplicate body names") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x: {parent: bed}
  x: {parent: bed}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:6:3", {"bodies", "duplicate body name 'x'", "line 5"});
}

TEST_CASE("bad: duplicate error names and aliases across the machine") {
  const std::string head = R"(weilgen: 1
name: bad
groups: [spindle]
error_defaults: {spindle: {sigma: 1}}
bodies:
  bed:
    errors:
      drift: {effect: translation, direction: x, group: spindle, aliases: [d1]}
  head:
    parent: bed
    errors:
)";
  const std::string ends = "tool: {body: head}\nworkpiece: {body: bed}\n";
  expect_error(head + "      drift: {effect: rotation, direction: z, group: spindle}\n" + ends,
               "bad.yaml:12:7", {"duplicate error name 'drift'", "line 8"});
  expect_error(
      head + "      sway: {effect: rotation, direction: z, group: spindle, aliases: [d1]}\n" + ends,
      "bad.yaml:12:72", {"duplicate alias 'd1'", "alias of error drift", "line 8"});
  expect_error(head + "      d1: {effect: rotation, direction: z, group: spindle}\n" + ends,
               "bad.yaml:12:7", {"duplicate error name 'd1'", "alias of error drift"});
}

TEST_CASE("bad: duplicate coordinate names") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x: {parent: bed, joint: {type: prismatic, axis: x, coordinate: X}, errors: none}
  x2: {parent: x, joint: {type: prismatic, axis: x, coordinate: X}, errors: none}
tool: {body: x2}
workpiece: {body: bed}
)",
               "bad.yaml:6:65",
               {"bodies.x2.joint.coordinate", "duplicate coordinate 'X'", "line 5"});
}

TEST_CASE("bad: coordinate named like a parameter") {
  expect_error(R"(weilgen: 1
name: bad
parameters: {X: 1}
bodies:
  bed: {}
  x: {parent: bed, joint: {type: prismatic, axis: x, coordinate: X}, errors: none}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:6:66", {"'X' is already the name of a parameter", "line 3"});
}

TEST_CASE("bad: unknown parent") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bedd
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:6:13", {"bodies.x.parent", "unknown parent 'bedd'", "bed, x"});
}

TEST_CASE("bad: no base body") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {parent: x}
  x: {parent: bed}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:3:1", {"bodies", "no base body"});
}

TEST_CASE("bad: more than one base body") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  column: {}
tool: {body: column}
workpiece: {body: bed}
)",
               "bad.yaml:5:3", {"more than one base body", "'bed' and 'column'"});
}

TEST_CASE("bad: cycle in parent links") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  a: {parent: c}
  b: {parent: a}
  c: {parent: b}
tool: {body: a}
workpiece: {body: bed}
)",
               "bad.yaml:5:15", {"bodies.a.parent", "cycle", "a -> c -> b -> a"});
  expect_error(
      "weilgen: 1\nname: bad\nbodies:\n  bed: {}\n  a: {parent: a}\n"
      "tool: {body: a}\nworkpiece: {body: bed}\n",
      "bad.yaml:5:15", {"bodies.a.parent", "own parent"});
}

TEST_CASE("bad: tool or workpiece body unknown") {
  const std::string head = "weilgen: 1\nname: bad\nbodies:\n  bed: {}\n";
  expect_error(head + "tool: {body: spindle}\nworkpiece: {body: bed}\n", "bad.yaml:5:14",
               {"tool.body", "unknown body 'spindle'"});
  expect_error(head + "tool: {body: bed}\nworkpiece: {body: table}\n", "bad.yaml:6:19",
               {"workpiece.body", "unknown body 'table'"});
}

TEST_CASE("bad: zero direction vectors") {
  const std::string head = "weilgen: 1\nname: bad\ngroups: [g]\nbodies:\n  bed: {}\n";
  const std::string ends = "tool: {body: bed}\nworkpiece: {body: bed}\n";
  expect_error(
      head + "  x: {parent: bed, joint: {type: prismatic, axis: [0, 0, 0], coordinate: X}}\n" +
          ends,
      "bad.yaml:6:51", {"bodies.x.joint.axis", "direction must not be zero"});
  expect_error(head +
                   "  x: {parent: bed, errors: {e: {effect: rotation, direction: [0, 0, 0], "
                   "group: g, sigma: 1}}}\n" +
                   ends,
               "bad.yaml:6:62", {"bodies.x.errors.e.direction", "direction must not be zero"});
  expect_error(
      head + "  x: {parent: bed, offset: {rotation: [{axis: [0, 0, 0], angle: 90}]}}\n" + ends,
      "bad.yaml:6:47", {"bodies.x.offset.rotation[0].axis", "must not be zero"});
  expect_error(
      head + "  x: {parent: bed, joint: {type: revolute, axis: w, coordinate: C}}\n" + ends,
      "bad.yaml:6:50", {"bodies.x.joint.axis", "unknown direction 'w'"});
}

TEST_CASE("bad: range with min > max") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X, range: [1000, 0]}
    errors: none
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:7:61", {"bodies.x.joint.range", "min 1000 is greater than max 0"});
}

TEST_CASE("bad: algebra order") {
  const std::string body =
      "weilgen: 1\nname: bad\nbodies: {bed: {}}\ntool: {body: bed}\nworkpiece: {body: bed}\n";
  expect_error(body + "algebra: {order: 0}\n", "bad.yaml:6:18", {"algebra.order", "from 1 to 20"});
  expect_error(body + "algebra: {order: 21}\n", "bad.yaml:6:18", {"algebra.order", "from 1 to 20"});
  expect_error(body + "algebra: {order: 1.5}\n", "bad.yaml:6:18",
               {"algebra.order", "whole number"});
  expect_error(body + "algebra: {order: two}\n", "bad.yaml:6:18",
               {"algebra.order", "whole number"});
}

TEST_CASE("bad: relation names an unknown error or group") {
  const std::string head = R"(weilgen: 1
name: bad
error_defaults: {angular: {sigma: 1}}
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors: {E_AX: {}, E_BX: {}}
tool: {body: x}
workpiece: {body: bed}
algebra:
  relations:
)";
  expect_error(head + "    - pair: [E_AX, E_CX]\n", "bad.yaml:14:20",
               {"algebra.relations[0].pair[1]", "relation names no error 'E_CX'"});
  expect_error(head + "    - squares: [E_AX]\n    - monomial: [E_QQ]\n", "bad.yaml:15:18",
               {"relation names no error 'E_QQ'"});
  expect_error(head + "    - between: [angular, wobble]\n", "bad.yaml:14:26",
               {"algebra.relations[0].between[1]", "relation names no group 'wobble'"});
  expect_error(head + "    - squares: some\n", "bad.yaml:14:16",
               {"algebra.relations[0].squares", "'all' or a list of error names"});
  expect_error(head + "    - pair: [E_AX, E_BX]\n      within: [angular]\n", "bad.yaml:14:7",
               {"algebra.relations[0]", "a relation is one of"});
}

TEST_CASE("bad: unknown group in an error or in error_defaults") {
  const std::string ends = "tool: {body: bed}\nworkpiece: {body: bed}\n";
  expect_error(
      "weilgen: 1\nname: bad\nbodies:\n  bed:\n    errors:\n"
      "      e: {effect: rotation, direction: z, group: wobble, sigma: 1}\n" +
          ends,
      "bad.yaml:6:50", {"bodies.bed.errors.e.group", "unknown group 'wobble'", "groups:"});
  expect_error(
      "weilgen: 1\nname: bad\nerror_defaults:\n  wobble: {sigma: 1}\nbodies: {bed: {}}\n" + ends,
      "bad.yaml:4:3", {"error_defaults", "unknown group 'wobble'"});
}

TEST_CASE("bad: units") {
  const std::string head = R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
)";
  const std::string ends = "tool: {body: x}\nworkpiece: {body: bed}\n";
  expect_error(head +
                   "    joint: {type: prismatic, axis: x, coordinate: X}\n"
                   "    errors: {E_XX: {sigma: 1, unit: furlong}}\n" +
                   ends,
               "bad.yaml:8:37", {"bodies.x.errors.E_XX.unit", "unknown unit 'furlong'", "arcsec"});
  expect_error(head + "    joint: {type: prismatic, axis: x, coordinate: X, unit: deg}\n" + ends,
               "bad.yaml:7:60", {"bodies.x.joint.unit", "unknown unit 'deg'", "mm, um, m"});
  expect_error(head +
                   "    joint: {type: prismatic, axis: x, coordinate: X}\n"
                   "    errors: {E_AX: {sigma: 1, unit: um}}\n" +
                   ends,
               "bad.yaml:8:37", {"unit 'um' is a length", "'E_AX' is a rotation"});
  expect_error(
      "weilgen: 1\nname: bad\nparameters: {L: {value: 1, unit: inch}}\n"
      "bodies: {bed: {}}\ntool: {body: bed}\nworkpiece: {body: bed}\n",
      "bad.yaml:3:34", {"parameters.L.unit", "unknown unit 'inch'"});
}

TEST_CASE("bad: unknown placement, effect, dependence, joint type") {
  const std::string head = R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors:
)";
  const std::string ends = "tool: {body: x}\nworkpiece: {body: bed}\n";
  expect_error(head + "      E_XX: {sigma: 1, placement: behind}\n" + ends, "bad.yaml:9:35",
               {"bodies.x.errors.E_XX.placement", "unknown value 'behind'", "after, before, axis"});
  expect_error(head + "      E_XX: {sigma: 1, effect: twist}\n" + ends, "bad.yaml:9:32",
               {"bodies.x.errors.E_XX.effect", "unknown value 'twist'", "translation, rotation"});
  expect_error(head + "      E_XX: {sigma: 1, dependence: PXGE}\n" + ends, "bad.yaml:9:36",
               {"bodies.x.errors.E_XX.dependence", "unknown value 'PXGE'", "PDGE, PIGE"});
  expect_error(
      "weilgen: 1\nname: bad\nbodies:\n  bed: {}\n  x: {parent: bed, joint: {type: "
      "sliding}}\ntool: {body: x}\nworkpiece: {body: bed}\n",
      "bad.yaml:5:34", {"bodies.x.joint.type", "unknown value 'sliding'"});
}

TEST_CASE("bad: custom error without effect, direction or group") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors:
      ball_screw: {effect: translation, sigma: 2}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:9:7",
               {"bodies.x.errors", "'ball_screw' is not an ISO 230-1 name", "custom",
                "missing: direction, group"});
}

TEST_CASE("bad: error without a distribution and no error_defaults for its group") {
  expect_error(R"(weilgen: 1
name: bad
error_defaults: {angular: {sigma: 1}}
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors:
      E_AX: {}
      E_YX: {unit: um}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:11:7",
               {"bodies.x.errors", "'E_YX' has no distribution", "group 'straightness'"});
  // The same through the ISO expansion of a body without an errors key.
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
tool: {body: x}
workpiece: {body: bed}
)",
               "bad.yaml:5:3", {"bodies.x", "'E_XX'", "implicit errors: iso", "no distribution"});
}

TEST_CASE("bad: distribution values") {
  const std::string head = R"(weilgen: 1
name: bad
parameters: {s: 1}
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors:
)";
  const std::string ends = "tool: {body: x}\nworkpiece: {body: bed}\n";
  expect_error(head + "      E_XX: {sigma: abc}\n" + ends, "bad.yaml:10:21",
               {"bodies.x.errors.E_XX.sigma", "expected a number, got 'abc'"});
  expect_error(head + "      E_XX: {sigma: 2*s}\n" + ends, "bad.yaml:10:21",
               {"E_XX.sigma", "expected a number"});
  expect_error(head + "      E_XX: {sigma: [1]}\n" + ends, "bad.yaml:10:21",
               {"E_XX.sigma", "expected a single value"});
  expect_error(head + "      E_XX: {sigma: .nan}\n" + ends, "bad.yaml:10:21",
               {"E_XX.sigma", "NaN"});
  expect_error(head + "      E_XX: {sigma: 1/0}\n" + ends, "bad.yaml:10:21",
               {"E_XX.sigma", "not a finite number"});
  expect_error(head + "      E_XX: {sigma: 0}\n" + ends, "bad.yaml:10:21",
               {"E_XX.sigma", "sigma must be positive"});
  expect_error(head + "      E_XX: {normal: [0, -1]}\n" + ends, "bad.yaml:10:26",
               {"E_XX.normal[1]", "sigma must be positive"});
  expect_error(head + "      E_XX: {uniform: [5, -5]}\n" + ends, "bad.yaml:10:23",
               {"E_XX.uniform", "lo (5) must be less than hi (-5)"});
  expect_error(head + "      E_XX: {truncnormal: [0, 1, 2, 2]}\n" + ends, "bad.yaml:10:27",
               {"E_XX.truncnormal", "must be less than hi"});
  expect_error(head + "      E_XX: {uniform: [1, 2, 3]}\n" + ends, "bad.yaml:10:23",
               {"E_XX.uniform", "expected [lo, hi]"});
  expect_error(head + "      E_XX: {sigma: 1, uniform: [-1, 1]}\n" + ends, "bad.yaml:10:24",
               {"E_XX", "one distribution", "'sigma' and 'uniform'"});
  expect_error(head + "      E_XX: {sigma: (1 +}\n" + ends, "bad.yaml:10:21",
               {"E_XX.sigma", "position"});
}

TEST_CASE("bad: errors: iso on a body without a joint") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {}
  table:
    parent: bed
    errors: iso
tool: {body: table}
workpiece: {body: bed}
)",
               "bad.yaml:7:13", {"bodies.table.errors", "'iso' needs a moving joint"});
}

TEST_CASE("bad: ISO name that does not fit the body's joint") {
  const std::string head = R"(weilgen: 1
name: bad
error_defaults: {straightness: {sigma: 1}, squareness: {sigma: 1}}
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X}
    errors:
)";
  const std::string ends = "tool: {body: x}\nworkpiece: {body: bed}\n";
  expect_error(
      head + "      E_XY: {}\n" + ends, "bad.yaml:10:7",
      {"'E_XY' is not an ISO 230-1 error of body 'x'", "coordinate Y", "joint coordinate is X"});
  expect_error(head + "      E_A0X: {}\n" + ends, "bad.yaml:10:7",
               {"'E_A0X'", "own direction has no meaning for a line"});
  expect_error(head + "      E_Y0X: {}\n" + ends, "bad.yaml:10:7",
               {"'E_Y0X'", "linear axis line has no location"});
  // With effect, direction and group an ISO-looking name is an ordinary custom error.
  CHECK(load_error(head + "      E_A0X: {effect: rotation, direction: x, group: squareness}\n" +
                   ends) == "(loaded without error)");
}

TEST_CASE("bad: ISO names on a skewed joint axis") {
  const std::string head = R"(weilgen: 1
name: bad
error_defaults: {straightness: {sigma: 1}}
bodies:
  bed: {}
  u:
    parent: bed
    joint: {type: prismatic, axis: [1, 1, 0], coordinate: U}
)";
  const std::string ends = "tool: {body: u}\nworkpiece: {body: bed}\n";
  expect_error(head + ends, "bad.yaml:6:3", {"bodies.u", "axis along x, y or z", "custom errors"});
  expect_error(head + "    errors: {E_YU: {}}\n" + ends, "bad.yaml:9:14",
               {"'E_YU' is not an ISO 230-1 error", "skewed"});
}

TEST_CASE("bad: unknown parameter in an expression") {
  const std::string head = "weilgen: 1\nname: bad\nparameters: {L01: 100}\nbodies:\n  bed: {}\n";
  const std::string ends = "tool: {body: bed}\nworkpiece: {body: bed}\n";
  expect_error(head + "  x: {parent: bed, offset: {translation: [0, 0, L01 + L99]}}\n" + ends,
               "bad.yaml:6:49",
               {"bodies.x.offset.translation[2]", "unknown parameter 'L99'", "declared: L01"});
  expect_error(head + "  x: {parent: bed, offset: {rotation: [{axis: z, angle: phi}]}}\n" + ends,
               "bad.yaml:6:57", {"bodies.x.offset.rotation[0].angle", "unknown parameter 'phi'"});
  expect_error(head + "tool: {body: bed, point: [0, 0, -tool_length]}\nworkpiece: {body: bed}\n",
               "bad.yaml:6:33", {"tool.point[2]", "unknown parameter 'tool_length'"});
  expect_error(head + "  x: {parent: bed, offset: {translation: [0, 0, L01 +]}}\n" + ends,
               "bad.yaml:6:49", {"bodies.x.offset.translation[2]", "position 6"});
}

TEST_CASE("bad: a moving joint on the base body") {
  expect_error(R"(weilgen: 1
name: bad
bodies:
  bed: {joint: {type: prismatic, axis: x, coordinate: X}, errors: none}
tool: {body: bed}
workpiece: {body: bed}
)",
               "bad.yaml:4:16", {"bodies.bed.joint", "base body"});
}

TEST_CASE("bad: the file is not a mapping") {
  expect_error("- just\n- a list\n", "bad.yaml:1:1", {"mapping"});
  expect_error("", "bad.yaml:1:1", {"mapping"});
}

TEST_CASE("shipped machines are found through $WEILGEN_MACHINES_DIR when it is set") {
  const std::string dir = std::string(WEILGEN_TEST_TMP) + "/machines_env";
  std::filesystem::create_directories(dir);
  {
    std::ofstream out(dir + "/only_here.yaml");
    out << "x: 1\n";
  }
  ::setenv("WEILGEN_MACHINES_DIR", dir.c_str(), 1);
  CHECK(weilgen::resolve_machine("only_here") == dir + "/only_here.yaml");
  CHECK_THROWS_AS(weilgen::resolve_machine("vmc_3axis"), weilgen::InputError);
  ::unsetenv("WEILGEN_MACHINES_DIR");
  CHECK(weilgen::resolve_machine("vmc_3axis").find("vmc_3axis.yaml") != std::string::npos);
}

TEST_CASE("machine loader: every error's to_base matches its unit (explicit, iso and defaults)") {
  const std::map<std::string, double> factor = {{"mm", 1.0},
                                                {"um", 1e-3},
                                                {"nm", 1e-6},
                                                {"rad", 1.0},
                                                {"mrad", 1e-3},
                                                {"urad", 1e-6},
                                                {"arcsec", M_PI / 648000},
                                                {"deg", M_PI / 180}};
  for (const auto& name : weilgen::test::shipped_machines()) {
    const auto d = weilgen::load_machine_file(weilgen::test::machine_path(name));
    for (const auto& e : d.errors) {
      CAPTURE(name);
      CAPTURE(e.name);
      REQUIRE(factor.count(e.unit) == 1);
      CHECK(e.to_base == doctest::Approx(factor.at(e.unit)).epsilon(1e-15));
    }
  }
}
