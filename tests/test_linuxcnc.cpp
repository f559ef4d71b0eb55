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
  for (const char* f : {"vmc_3axis.hpp", "vmc_3axis_c.h", "vmc_3axis_c.cpp",
                        "weilgen_vmc_3axis_hal.c", "weilgen_vmc_3axis_errors.cpp", "Makefile",
                        "weilgen_vmc_3axis.hal", "vmc_3axis_params.hpp"}) {
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
  const std::string errors = test::read_text((dir / "weilgen_vmc_3axis_errors.cpp").string());
  CHECK(errors.find("#include \"vmc_3axis_params.hpp\"") != std::string::npos);
  CHECK(errors.find("identified::Errors(q, &e)") != std::string::npos);
  CHECK(test::read_text((dir / "Makefile").string()).find("COMPONENT := weilgen_vmc_3axis") !=
        std::string::npos);
  const std::string lines = test::read_text((dir / "weilgen_vmc_3axis.hal").string());
  CHECK(lines.find("net x-pos-cmd joint.0.motor-pos-cmd => weilgen_vmc_3axis.x.pos-cmd") !=
        std::string::npos);
  CHECK(lines.find("net y-pos-fb weilgen_vmc_3axis.y.pos-fb => joint.1.motor-pos-fb") !=
        std::string::npos);

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
