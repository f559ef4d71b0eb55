// `weilgen linuxcnc` without LinuxCNC (docs/controllers.md): the files it writes and its
// refusals. The component itself is built and run under halrun by CTest linuxcnc_component
// (tests/linuxcnc/run_component_test.py).
#include <doctest/doctest.h>

#include <filesystem>

#include "test_support.hpp"

using namespace weilgen;
namespace fs = std::filesystem;

namespace {

std::string params_header() { return std::string(WEILGEN_GENERATED_DIR) + "/vmc_3axis_params.hpp"; }

}  // namespace

TEST_CASE("weilgen linuxcnc writes the component, its C API, Makefile and configuration lines") {
  const fs::path dir = test::fresh_dir("linuxcnc_files") / "comp";
  const test::Run r = test::run(
      test::cli("linuxcnc vmc_3axis --params " + params_header() + " --out " + dir.string()));
  INFO(r.out);
  REQUIRE(r.status == 0);
  for (const char* f :
       {"vmc_3axis.hpp", "vmc_3axis_c.h", "vmc_3axis_c.cpp", "weilgen_vmc_3axis_hal.c",
        "weilgen_vmc_3axis_errors.cpp", "Makefile", "weilgen_vmc_3axis.hal", "vmc_3axis_params.hpp",
        "vmc_3axis_params_file.h", "vmc_3axis_params_file.c"}) {
    CAPTURE(f);
    CHECK(fs::exists(dir / f));
  }
  // The model header and C API are the committed ones; the parameters a verbatim copy.
  CHECK(test::read_text((dir / "vmc_3axis_c.h").string()) ==
        test::read_text(std::string(WEILGEN_SOURCE_DIR) + "/generated/vmc_3axis_c.h"));
  CHECK(test::read_text((dir / "vmc_3axis_params.hpp").string()) ==
        test::read_text(params_header()));
  const std::string hal = test::read_text((dir / "weilgen_vmc_3axis_hal.c").string());
  CHECK(hal.find("#define COMPONENT \"weilgen_vmc_3axis\"") != std::string::npos);
  CHECK(hal.find("axis_pins[VMC_3AXIS_NUM_AXES] = {\"y\", \"x\", \"z\"}") != std::string::npos);
  CHECK(hal.find("standin") == std::string::npos);
  CHECK(hal.find("vmc_3axis_compensate_at(") != std::string::npos);
  // kAxes Y, X, Z: X and Y carry the table (sign -1), Z the tool; limits in mm.
  CHECK(hal.find("axis_sign[VMC_3AXIS_NUM_AXES] = {-1.0, -1.0, 1.0}") != std::string::npos);
  CHECK(hal.find("travel_max[VMC_3AXIS_NUM_AXES] = {0.0, 5e+02, 0.0}") != std::string::npos);
  CHECK(hal.find("default_max_correction[VMC_3AXIS_NUM_AXES] = {0.1, 0.1, 0.1}") !=
        std::string::npos);
  CHECK(hal.find("#define IDENTIFIED_BUILT_IN 1") != std::string::npos);
  CHECK(test::read_text((dir / "vmc_3axis_params_file.c").string())
            .find("int vmc_3axis_params_parse(") != std::string::npos);
  const std::string errors = test::read_text((dir / "weilgen_vmc_3axis_errors.cpp").string());
  CHECK(errors.find("#include \"vmc_3axis_params.hpp\"") != std::string::npos);
  CHECK(errors.find("identified::Errors(q, &e)") != std::string::npos);
  CHECK(test::read_text((dir / "Makefile").string()).find("COMPONENT := weilgen_vmc_3axis") !=
        std::string::npos);
  const std::string lines = test::read_text((dir / "weilgen_vmc_3axis.hal").string());
  for (const char* line :
       {"#   [KINS] KINEMATICS = trivkins coordinates=XYZ\n",
        "net weilgen-x-pos-cmd joint.0.pos-cmd => weilgen_vmc_3axis.x.pos-cmd\n",
        "net weilgen-x-motor-cmd joint.0.motor-pos-cmd => weilgen_vmc_3axis.x.motor-pos-cmd\n",
        "net weilgen-x-pos-comp weilgen_vmc_3axis.x.pos-comp\n",
        "net weilgen-x-pos-fb-in => weilgen_vmc_3axis.x.pos-fb-in\n",
        "net weilgen-y-motor-fb weilgen_vmc_3axis.y.pos-fb => joint.1.motor-pos-fb\n",
        "net machine-is-enabled motion.motion-enabled => weilgen_vmc_3axis.enable\n",
        "net weilgen-all-homed motion.is-all-homed => weilgen_vmc_3axis.homed\n",
        "addf weilgen_vmc_3axis.feedback servo-thread -2\n",
        "setp weilgen_vmc_3axis.z.max-step 0.001  # mm per servo period\n",
        "net weilgen-fault weilgen_vmc_3axis.fault\n"}) {
    CAPTURE(line);
    CHECK(lines.find(line) != std::string::npos);
  }

  // Without identified parameters the errors start at zero (or the JSON's values).
  const fs::path plain = test::fresh_dir("linuxcnc_plain");
  const std::string json = (plain / "errors.json").string();
  write_file_atomically(json,
                        "{\"weilgen_tolerances\": 1, \"errors\": {\"E_XX\": {\"const\": 2, "
                        "\"unit\": \"um\"}, \"dx(y)\": {\"const\": -3, \"unit\": \"um\"}}}\n");
  const test::Run p = test::run(test::cli("linuxcnc vmc_3axis --name vmc --params " + json +
                                          " --out " + (plain / "c").string()));
  INFO(p.out);
  REQUIRE(p.status == 0);
  const std::string c = test::read_text((plain / "c" / "vmc_hal.c").string());
  // kErrors order: E_XY (alias dx(y)) first, E_XX eighth; base units mm.
  CHECK(c.find("error_defaults[VMC_3AXIS_NUM_ERRORS] = {-0.003, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, "
               "0.002, ") != std::string::npos);
  CHECK(test::read_text((plain / "c" / "vmc_errors.cpp").string()).find("errors[i] = 0.0") !=
        std::string::npos);
  CHECK(!fs::exists(plain / "c" / "vmc_3axis_params.hpp"));
}

TEST_CASE("weilgen linuxcnc refuses bad parameters, names and outputs, writing nothing") {
  const fs::path dir = test::fresh_dir("linuxcnc_bad");
  const std::string out = (dir / "out").string();
  const auto refused = [&](const std::string& args, int status, const std::string& message) {
    const test::Run r = test::run(test::cli("linuxcnc " + args));
    INFO(args, r.out);
    CHECK(r.status == status);
    CHECK(r.out.find(message) != std::string::npos);
    CHECK(!fs::exists(out));
  };
  // Parameters identified for another model: the namespace or the model key.
  const std::string other = (dir / "other_params.hpp").string();
  std::string text = test::read_text(params_header());
  write_file_atomically(other, text);
  refused("five_axis_ac --params " + other + " --out " + out, 3,
          "not the identified parameters of model five_axis_ac");
  const auto key = text.find("kModelKey = \"");
  REQUIRE(key != std::string::npos);
  text.replace(key + 13, 4, "ffff");
  write_file_atomically(other, text);
  refused("vmc_3axis --params " + other + " --out " + out, 3, "other_params.hpp:");
  refused("vmc_3axis --params " + other + " --out " + out, 3, "identify again");

  const std::string json = (dir / "spread.json").string();
  write_file_atomically(json,
                        "{\"weilgen_tolerances\": 1,\n \"errors\": {\n  \"E_XX\": {\"sigma\": 2, "
                        "\"unit\": \"um\"}}}\n");
  refused("vmc_3axis --params " + json + " --out " + out, 3, "spread.json:3");
  refused("vmc_3axis --params " + (dir / "x.txt").string() + " --out " + out, 2, "expected a .hpp");
  refused("vmc_3axis --name 9lives --out " + out, 2, "--name 9lives");
  refused("vmc_3axis --name " + std::string(40, 'a') + " --out " + out, 2, "HAL allows 47");
  refused("vmc_3axis", 2, "no --out");
  refused("vmc_3axis --out " + other, 2, "is not a directory");
  // The parameters' copy would overwrite the parameters given.
  const fs::path same = test::fresh_dir("linuxcnc_same");
  const std::string inside = (same / "vmc_3axis_params.hpp").string();
  write_file_atomically(inside, test::read_text(params_header()));
  const test::Run r =
      test::run(test::cli("linuxcnc vmc_3axis --params " + inside + " --out " + same.string()));
  INFO(r.out);
  CHECK(r.status == 2);
  CHECK(r.out.find("is the input") != std::string::npos);
  CHECK(!fs::exists(same / "Makefile"));
}

TEST_CASE("weilgen linuxcnc: units, signs, offsets and a params file of the right model") {
  const fs::path dir = test::fresh_dir("linuxcnc_joints");
  const std::string data = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/vmc_3axis_points.csv";
  const std::string json = (dir / "vmc_params.json").string();
  const test::Run id =
      test::run(test::cli("identify vmc_3axis -q --data " + data + " --emit-params-json " + json));
  INFO(id.out);
  REQUIRE(id.status == 0);
  const std::string out = (dir / "inch").string();
  const test::Run r =
      test::run(test::cli("linuxcnc vmc_3axis --units inch --sign Z=-1 --offset "
                          "X=250 --params-file " +
                          json + " --out " + out));
  INFO(r.out);
  REQUIRE(r.status == 0);
  const std::string c = test::read_text(out + "/weilgen_vmc_3axis_hal.c");
  CHECK(c.find("axis_sign[VMC_3AXIS_NUM_AXES] = {-1.0, -1.0, -1.0}") != std::string::npos);
  CHECK(c.find("axis_scale[VMC_3AXIS_NUM_AXES] = {25.4, 25.4, 25.4}") != std::string::npos);
  CHECK(c.find("axis_offset[VMC_3AXIS_NUM_AXES] = {0.0, 2.5e+02, 0.0}") != std::string::npos);
  // 0.1 mm and 1 um per period in inch.
  CHECK(c.find("default_max_correction[VMC_3AXIS_NUM_AXES] = {0.003937007874015749, ") !=
        std::string::npos);
  CHECK(c.find("#define IDENTIFIED_BUILT_IN 0") != std::string::npos);
  const std::string hal = test::read_text(out + "/weilgen_vmc_3axis.hal");
  CHECK(hal.find("loadrt weilgen_vmc_3axis params_file=" + json + "\n") != std::string::npos);
  CHECK(hal.find("#   [TRAJ] LINEAR_UNITS = inch") != std::string::npos);
  CHECK(hal.find("model X = 250 - 25.4 * joint (mm)") != std::string::npos);
  CHECK(hal.find("#   Z  2  Z  -1  25.4  0  inch  --sign") != std::string::npos);

  const auto refused = [&](const std::string& args, int status, const std::string& message) {
    const std::string never = (dir / "never").string();
    const test::Run x = test::run(test::cli("linuxcnc " + args + " --out " + never));
    INFO(args, x.out);
    CHECK(x.status == status);
    CHECK(x.out.find(message) != std::string::npos);
    CHECK(!fs::exists(never));
  };
  refused("vmc_3axis --units cm", 2, "--units cm: mm or inch");
  refused("vmc_3axis --sign X=2", 2, "--sign X=2: a sign is 1 or -1");
  refused("vmc_3axis --sign A=1", 2, "'A' is not an axis of vmc_3axis");
  refused("vmc_3axis --offset X=1deg", 2, "X is in mm, not deg");
  refused("five_axis_ac --params-file " + json, 3,
          "the parameters of machine 'vmc_3axis', not of five_axis_ac");
  refused("vmc_3axis --params " + json, 2, "give them as --params-file");
  std::string other = test::read_text(json);
  other.replace(other.find("\"model_key\": \"") + 14, 4, "ffff");
  const std::string stale = (dir / "stale.json").string();
  write_file_atomically(stale, other);
  refused("vmc_3axis --params-file " + stale, 3, "stale.json: model_key \"ffff");
  refused("vmc_3axis --params-file " + (dir / "none.json").string(), 3, "cannot read");
}
