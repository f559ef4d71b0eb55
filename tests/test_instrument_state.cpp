// The instrument's compensation state and --normalise (weilgen/measure/normalisation.hpp,
// docs/iso230-2.md "Instrument compensation state"): every combination of what the file says
// (material_compensation, air_compensation), where the coefficient and the air mode come from
// (header key or flag) and the mode, against a table of the rule written out here; the
// conflicts a flag cannot win are refused naming the flag; the CLI states the decision in the
// text, JSON and report, and refuses the conflicts with exit 2.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <optional>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/measure/normalisation.hpp"

using namespace weilgen;
using nlohmann::json;
using test::cli;
using test::run;

namespace {

// One bidirectional run at 0 and 500 mm, material at 21 degC, the air recorded.
std::string data(const std::string& keys) {
  return "# axis: X\n" + keys +
         "X,dir,cycle,dx_um,T_material,T_air,p_air_Pa,RH_air_pct\n"
         "0,1,1,0,21,20,101325,50\n500,1,1,0,21,20,101325,50\n"
         "500,-1,1,0,21,20,101325,50\n0,-1,1,0,21,20,101325,50\n"
         "0,1,2,0,21,20,101325,50\n500,1,2,0,21,20,101325,50\n"
         "500,-1,2,0,21,20,101325,50\n0,-1,2,0,21,20,101325,50\n";
}

struct Outcome {
  bool refused = false;  // std::invalid_argument (a flag the rule cannot follow)
  bool material = false, air = false;
  std::string message;
};

Outcome normalise(const std::string& keys, NormalisationOptions o) {
  const MeasurementTable t = parse_measurements(data(keys), "s.csv");
  std::vector<IsoObservation> obs = iso_observations(t, iso_columns(t));
  Outcome out;
  try {
    const NormalisationResult r =
        normalise_observations(t, obs, normalisation_with_header_keys(o, t), "um");
    out.material = r.material_applied;
    out.air = r.air_applied;
  } catch (const std::invalid_argument& e) {
    out.refused = true;
    out.message = e.what();
  }
  return out;
}

}  // namespace

TEST_CASE("instrument state: the material's expansion, every state, source and mode") {
  // The rule (docs/iso230-2.md): never applies nothing (an --expansion flag is refused); force
  // applies whenever alpha is known; auto applies unless the file says the instrument did
  // (an --expansion flag then refused), and for a laser export that does not say, only a
  // flag's alpha.
  const char* states[] = {"", "unstated", "instrument", "none"};
  const char* sources[] = {"no alpha", "header", "flag"};
  const NormaliseMode modes[] = {NormaliseMode::Auto, NormaliseMode::Force, NormaliseMode::Never};
  int cases = 0;
  for (const std::string state : states)
    for (const std::string source : sources)
      for (const NormaliseMode mode : modes) {
        std::string keys;
        if (!state.empty()) keys += "# material_compensation: " + state + "\n";
        if (source == "header") keys += "# expansion_ppm_per_K: 11.7\n";
        NormalisationOptions o;
        o.mode = mode;
        if (source == "flag") o.expansion_ppm_per_K = 11.7;
        const bool alpha = source != "no alpha", flag = source == "flag";
        bool refused = false, applied = false;
        if (mode == NormaliseMode::Never) {
          refused = flag;
        } else if (mode == NormaliseMode::Force) {
          applied = alpha;
        } else if (state == "instrument") {
          refused = flag;
        } else if (state == "unstated") {
          applied = flag;
        } else {
          applied = alpha;
        }
        const Outcome got = normalise(keys, o);
        CAPTURE(state);
        CAPTURE(source);
        CAPTURE(to_string(mode));
        CHECK(got.refused == refused);
        if (!refused) CHECK(got.material == applied);
        if (refused) CHECK(got.message.rfind("--expansion 11.7: ", 0) == 0);
        ++cases;
      }
  CHECK(cases == 36);
  // The messages say what to do.
  NormalisationOptions o;
  o.expansion_ppm_per_K = 11.7;
  CHECK(normalise("# material_compensation: instrument\n", o).message ==
        "--expansion 11.7: s.csv:2 says the instrument already corrected the readings to 20 degC "
        "(material_compensation: instrument); a second correction doubles it (11.7 um/m per K); "
        "--normalise force applies it anyway");
  o.mode = NormaliseMode::Never;
  CHECK(normalise("", o).message ==
        "--expansion 11.7: --normalise never applies no correction; drop one of them");
  // alpha = 0 corrects nothing and says so, whatever the mode.
  NormalisationOptions zero;
  zero.expansion_ppm_per_K = 0;
  zero.mode = NormaliseMode::Force;
  CHECK_FALSE(normalise("", zero).material);
}

TEST_CASE("instrument state: the air, every file statement, flag and mode") {
  // The rule: never corrects nothing (--air-compensation edlen refused); a flag instrument or
  // none corrects nothing; a flag edlen corrects, refused in auto when the file says the
  // instrument compensated; without a flag: the file's instrument nothing, edlen corrects, none
  // corrects when the air values are recorded (they are here), unstated nothing.
  const std::optional<AirCompensation> in_file[] = {std::nullopt, AirCompensation::Instrument,
                                                    AirCompensation::None, AirCompensation::Edlen};
  const std::optional<AirCompensation> flags[] = {std::nullopt, AirCompensation::Instrument,
                                                  AirCompensation::None, AirCompensation::Edlen};
  const NormaliseMode modes[] = {NormaliseMode::Auto, NormaliseMode::Force, NormaliseMode::Never};
  int cases = 0;
  for (const auto& f : in_file)
    for (const auto& flag : flags)
      for (const NormaliseMode mode : modes) {
        std::string keys;
        if (f) keys += std::string("# air_compensation: ") + to_string(*f) + "\n";
        NormalisationOptions o;
        o.mode = mode;
        if (flag) o.air = *flag;
        bool refused = false, applied = false;
        if (mode == NormaliseMode::Never) {
          refused = flag == AirCompensation::Edlen;
        } else if (flag) {
          if (*flag == AirCompensation::Edlen) {
            refused = mode == NormaliseMode::Auto && f == AirCompensation::Instrument;
            applied = !refused;
          }
        } else {
          applied = f == AirCompensation::Edlen || f == AirCompensation::None;
        }
        const Outcome got = normalise(keys, o);
        CAPTURE(f ? to_string(*f) : "absent");
        CAPTURE(flag ? to_string(*flag) : "no flag");
        CAPTURE(to_string(mode));
        CHECK(got.refused == refused);
        if (!refused) CHECK(got.air == applied);
        ++cases;
      }
  CHECK(cases == 48);
  // The file says the instrument did not compensate, but records no air: nothing corrected.
  const MeasurementTable t = parse_measurements(
      "# axis: X\n# air_compensation: none\nX,dir,cycle,dx_um\n0,1,1,0\n0,1,2,0\n0,-1,1,0\n"
      "0,-1,2,0\n",
      "n.csv");
  std::vector<IsoObservation> obs = iso_observations(t, iso_columns(t));
  const NormalisationResult r =
      normalise_observations(t, obs, normalisation_with_header_keys({}, t), "um");
  CHECK_FALSE(r.air_applied);
  CHECK(r.air_decision ==
        "n.csv:2 says air_compensation: none and the file records no air temperature, pressure "
        "and humidity");
  NormalisationOptions edlen;
  edlen.air = AirCompensation::Edlen;
  CHECK(normalise("# air_compensation: instrument\n", edlen).message ==
        "--air-compensation edlen: s.csv:2 says the instrument already compensated the air "
        "(air_compensation: instrument); a second correction doubles it (about 271 um/m); "
        "--normalise force applies it anyway");
  CHECK(parse_normalise_mode("FORCE") == NormaliseMode::Force);
  CHECK_THROWS_WITH_AS(parse_normalise_mode("sometimes"),
                       doctest::Contains("--normalise sometimes: expected auto"),
                       std::invalid_argument);
}

TEST_CASE("instrument state: the CLI states the decision and refuses conflicts with exit 2") {
  const auto dir = test::fresh_dir("instrument_state_cli");
  const std::string carto = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/carto_x.csv";
  const std::string js = (dir / "c.json").string(), html = (dir / "c.html").string();
  // The shipped export says 'Material Compensation,Off' and 'Air Compensation,Automatic':
  // normalised once by weilgen, the air left to the instrument.
  test::Run r = run(cli("iso230-2 " + carto + " --json " + js + " --report " + html));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("Normalised to 20 degC by weilgen (ISO 1; --normalise auto): " + carto +
                   ":10 says material_compensation: none; corrected with alpha 11.7 um/(m K) "
                   "(header key expansion_ppm_per_K)") != std::string::npos);
  CHECK(r.out.find("Air refraction compensated by the instrument: " + carto +
                   ":11 says air_compensation: instrument") != std::string::npos);
  json j = json::parse(test::read_text(js));
  CHECK(j["normalisation"]["mode"] == "auto");
  CHECK(j["normalisation"]["material"]["instrument_state"] == "none");
  CHECK(j["normalisation"]["material"]["applied"] == true);
  CHECK(j["normalisation"]["air"]["instrument_state"] == "instrument");
  CHECK(j["normalisation"]["air"]["applied"] == false);
  CHECK(j["E_um"].get<double>() == doctest::Approx(9.234).epsilon(1e-3));
  CHECK(test::read_text(html).find("says material_compensation: none") != std::string::npos);
  // never: the raw readings (the docs' 26.784 um).
  r = run(cli("iso230-2 " + carto + " --normalise never --json " + js));
  REQUIRE(r.status == 0);
  j = json::parse(test::read_text(js));
  CHECK(j["normalisation"]["material"]["applied"] == false);
  CHECK(j["E_um"].get<double>() == doctest::Approx(26.784).epsilon(1e-3));
  // The same export saying 'On': not normalised again; --expansion is refused, force doubles.
  std::string text = test::read_text(carto);
  text.replace(text.find("Material Compensation,Off"), 25, "Material Compensation,On");
  const std::string on = (dir / "on.csv").string();
  write_file_atomically(on, text);
  r = run(cli("iso230-2 " + on + " --json " + js));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("Normalised to 20 degC by the instrument, not by weilgen") != std::string::npos);
  CHECK(json::parse(test::read_text(js))["E_um"].get<double>() ==
        doctest::Approx(26.784).epsilon(1e-3));
  write_file_atomically(js, "keep\n");
  r = run(cli("iso230-2 " + on + " --expansion 11.7 --json " + js));
  CHECK(r.status == 2);
  CHECK(r.out.find("--expansion 11.7: " + on + ":10 says the instrument already corrected") !=
        std::string::npos);
  CHECK(test::read_text(js) == "keep\n");
  CHECK(run(cli("iso230-2 " + on + " --air-compensation edlen")).status == 2);
  CHECK(run(cli("iso230-2 " + carto + " --normalise sometimes")).status == 2);
  r = run(cli("iso230-2 " + on + " --normalise force --json " + js));
  REQUIRE(r.status == 0);
  CHECK(json::parse(test::read_text(js))["normalisation"]["material"]["applied"] == true);
}
