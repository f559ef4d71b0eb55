// Laser exports read into the tidy layout (weilgen/measure/instrument_import.hpp,
// docs/data-format.md "Instrument files"): fixtures written here to the documented CARTO and
// generic wide shapes, the hand-computed ISO 230-2 example of docs/iso230-2.md carried through
// each of them (every figure equal to the tidy file's), units, separators, per-run columns,
// every bad input with its file:line:column, the tidy writer's round trip, and the CLI.
#include <doctest/doctest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/measure/instrument_import.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/report/measurement_document.hpp"

using namespace weilgen;
using nlohmann::json;
using test::cli;
using test::run;

namespace {

std::string small_csv() {
  return std::string(WEILGEN_SOURCE_DIR) + "/examples/data/iso230_2_small.csv";
}

// The hand-computed example (docs/iso230-2.md) as a CARTO export: metadata lines, a blank line,
// the header row, one row per target and direction, runs as columns.
const char* const kCartoSmall =
    "Renishaw XL-80 linear test (a fixture in the shape of docs/data-format.md)\n"
    "Machine,Test rig 7\n"
    "Axis,X axis\n"
    "Date,2024-05-02 09:14\n"
    "Operator,\"Other, A. N.\"\n"
    "Air Compensation,Automatic\n"
    "Material Expansion Coefficient (ppm/\xC2\xB0"
    "C),11.5\n"
    "\n"
    "Target Position (mm),Direction,Run 1 (\xC2\xB5m),Run 2 (\xC2\xB5m),Run 3 (\xC2\xB5m),"
    "Air Temperature (\xC2\xB0"
    "C),Air Pressure (mbar),Humidity (%),"
    "Material Temperature (\xC2\xB0"
    "C)\n"
    "0.000,Forward,1,2,3,20.1,1013.2,45,20.0\n"
    "100.000,Forward,4,6,8,20.1,1013.2,45,20.0\n"
    "200.000,Forward,0,3,6,20.2,1013.1,45,20.0\n"
    "200.000,Reverse,5,7,9,20.2,1013.1,46,20.0\n"
    "100.000,Reverse,4,4,4,20.2,1013.0,46,20.0\n"
    "0.000,Reverse,-2,-1,0,20.3,1013.0,46,20.0\n";

// The same as the generic wide form.
const char* const kWideSmall =
    "# format: wide\n"
    "# axis: X\n"
    "# machine: Test rig 7\n"
    "X,dir,dx_um@1,dx_um@2,dx_um@3,t_s@1,t_s@2,t_s@3,T_air\n"
    "0,1,1,2,3,0,360,720,20.1\n"
    "100,1,4,6,8,60,420,780,20.1\n"
    "200,1,0,3,6,120,480,840,20.2\n"
    "200,-1,5,7,9,180,540,900,20.2\n"
    "100,-1,4,4,4,240,600,960,20.2\n"
    "0,-1,-2,-1,0,300,660,1020,20.3\n";

std::string error_of(const std::string& text, ImportOptions o = {}) {
  try {
    parse_instrument_text(text, "f.csv", o);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::invalid_argument& e) {
    return std::string("invalid_argument: ") + e.what();
  }
  FAIL("no error for:\n" << text);
  return "";
}

// Every classical figure and the drift-eliminated A of two studies are equal.
void check_same_figures(const Iso230_2StudyResult& a, const Iso230_2StudyResult& b) {
  const IsoFigures &fa = a.classical.figures, &fb = b.classical.figures;
  for (double IsoFigures::*f :
       {&IsoFigures::A, &IsoFigures::A_up, &IsoFigures::A_down, &IsoFigures::R, &IsoFigures::R_up,
        &IsoFigures::R_down, &IsoFigures::E, &IsoFigures::E_up, &IsoFigures::E_down, &IsoFigures::M,
        &IsoFigures::B, &IsoFigures::B_mean})
    CHECK(fa.*f == doctest::Approx(fb.*f).epsilon(1e-12));
  REQUIRE(a.drift.has_value());
  REQUIRE(b.drift.has_value());
  CHECK(a.drift->figures.A == doctest::Approx(b.drift->figures.A).epsilon(1e-12));
  CHECK(a.runs.positions_mm == b.runs.positions_mm);
}

Iso230_2StudyResult study(const MeasurementTable& t) { return Iso230_2Study({}).run(t); }

}  // namespace

TEST_CASE("import: formats are detected from the text") {
  CHECK(detect_instrument_format(kCartoSmall) == InstrumentFormat::Carto);
  CHECK(detect_instrument_format(kWideSmall) == InstrumentFormat::Wide);
  CHECK(detect_instrument_format("# axis: X\nX,dir,cycle,dx_um\n0,1,1,0\n") ==
        InstrumentFormat::Tidy);
  CHECK(detect_instrument_format("Target (deg);Direction;Run 1 (arcsec)\n") ==
        InstrumentFormat::Carto);
  CHECK(parse_instrument_format("CARTO") == InstrumentFormat::Carto);
  CHECK_THROWS_AS(parse_instrument_format("rtl"), std::invalid_argument);
}

TEST_CASE("import: a CARTO export becomes one tidy row per run with its environment") {
  const ImportResult r = parse_instrument_text(kCartoSmall, "carto.csv");
  const MeasurementTable& t = r.table;
  CHECK(r.format == InstrumentFormat::Carto);
  CHECK(r.source_rows == 6);
  REQUIRE(t.rows() == 18);
  CHECK(t.columns == std::vector<std::string>{"X", "dir", "T_air", "p_air_Pa", "RH_air_pct",
                                              "T_material", "cycle", "dx_um"});
  // Row 1 = line 10 (target 0, Forward), runs 1..3.
  CHECK(t.lines[0] == 10);
  CHECK(t.lines[2] == 10);
  CHECK(t.column("cycle")[2] == 3);
  CHECK(t.column("dx_um")[2] == 3);
  CHECK(t.column("dir")[17] == -1);
  CHECK(t.column("X")[17] == 0);
  CHECK(t.column("dx_um")[17] == 0);
  CHECK(t.column("p_air_Pa")[0] == doctest::Approx(101320));  // 1013.2 mbar
  CHECK(t.info_of("p_air_Pa").unit == "Pa");
  CHECK(t.info_of("X").role == ColumnRole::Coordinate);
  // Metadata as header keys, with the expansion coefficient and the compensation mapped.
  CHECK(t.header_key("machine") == "Test rig 7");
  CHECK(t.header_key("axis") == "X");
  CHECK(t.header_key("operator") == "Other, A. N.");
  CHECK(t.header_key("air_compensation") == "instrument");
  CHECK(t.header_key("expansion_ppm_per_K") == "11.5");
  CHECK(t.header_key_lines.at("date") == 4);
  // The mapping, one line per source column.
  REQUIRE(r.mapping.size() == 9);
  CHECK(r.mapping[0] == "'Target Position (mm)' -> X (mm)");
  CHECK(r.mapping[1] == "'Direction' -> dir (Forward = +1, Reverse = -1)");
  CHECK(r.mapping[2] == "'Run 1 (\xC2\xB5m)' -> dx_um of cycle 1 (um)");
  CHECK(r.mapping[5] ==
        "'Air Temperature (\xC2\xB0"
        "C)' -> T_air (degC)");
  CHECK(r.mapping[6] == "'Air Pressure (mbar)' -> p_air_Pa (Pa, x 100)");
}

TEST_CASE("import: the hand-computed example gives the same figures from tidy, CARTO and wide") {
  const Iso230_2StudyResult tidy = study(read_measurements(small_csv()));
  const Iso230_2StudyResult carto = study(parse_instrument_text(kCartoSmall, "c.csv").table);
  const Iso230_2StudyResult wide = study(parse_instrument_text(kWideSmall, "w.csv").table);
  check_same_figures(carto, tidy);
  check_same_figures(wide, tidy);
  CHECK(carto.classical.figures.A == doctest::Approx(14));  // docs/iso230-2.md
  CHECK(wide.classical.figures.R == doctest::Approx(14));
  // The CARTO file gives a coefficient but not whether its software applied it: not normalised
  // again (docs/iso230-2.md, "Instrument compensation state"); its air values are reported, the
  // instrument compensated them.
  CHECK_FALSE(carto.normalisation.material_applied);
  CHECK(carto.normalisation.material_compensation == "unstated");
  CHECK(carto.normalisation.air == AirCompensation::Instrument);
  CHECK(carto.normalisation.air_temperature_C.max == doctest::Approx(20.3));
  // The wide file's per-cycle times give the drift rate per hour.
  CHECK(wide.runs.has_time);
  CHECK(wide.drift->per_cycle.rate_per_h == doctest::Approx(1.5 / 0.1).epsilon(1e-9));
}

TEST_CASE("import: separators, decimal commas, quotes, BOM, CRLF, units and rotary axes") {
  // Semicolons with decimal commas, a BOM and CRLF line ends, mm runs, hPa, per-run material
  // temperature columns and two sensors.
  const std::string semi =
      "\xEF\xBB\xBF"
      "Axis;Y\r\n"
      "\"Target Position (mm)\";Direction;Run 1 (mm);Run 2 (mm);Air Pressure (hPa);"
      "Run 1 Material Temperature 1 (\xC2\xB0"
      "C);Run 2 Material Temperature 1 (\xC2\xB0"
      "C);"
      "Material Temperature 2 (\xC2\xB0"
      "C)\r\n"
      "0,0;Fwd;0,001;0,002;1013,25;20,5;20,7;21,0\r\n"
      "0,0;Bwd;-0,001;;1013,25;20,5;20,7;21,0\r\n";
  const ImportResult r = parse_instrument_text(semi, "semi.csv");
  const MeasurementTable& t = r.table;
  CHECK(t.columns == std::vector<std::string>{"Y", "dir", "p_air_Pa", "T_material_2", "cycle",
                                              "dy_um", "T_material_1"});
  REQUIRE(t.rows() == 3);  // run 2 reverse is not measured
  CHECK(t.column("dy_um")[0] == doctest::Approx(1));
  CHECK(t.column("dy_um")[1] == doctest::Approx(2));
  CHECK(t.column("dy_um")[2] == doctest::Approx(-1));
  CHECK(t.column("p_air_Pa")[0] == doctest::Approx(101325));
  CHECK(t.column("T_material_1")[0] == doctest::Approx(20.5));
  CHECK(t.column("T_material_1")[1] == doctest::Approx(20.7));
  CHECK(t.column("T_material_2")[1] == doctest::Approx(21.0));
  // A rotary axis: degrees and arcseconds (to urad), Fahrenheit, minutes.
  const std::string rot =
      "Axis,C\nTarget (deg),Direction,Run 1 (arcsec),Run 1 Time (min),Air Temperature (degF)\n"
      "90,+,1,2,68\n";
  const MeasurementTable c = parse_instrument_text(rot, "rot.csv").table;
  CHECK(c.columns == std::vector<std::string>{"C", "dir", "T_air", "cycle", "dc_urad", "t_s"});
  CHECK(c.column("dc_urad")[0] == doctest::Approx(4.84813681));
  CHECK(c.column("t_s")[0] == 120);
  CHECK(c.column("T_air")[0] == doctest::Approx(20));
  CHECK(c.info_of("C").unit == "deg");
  // The axis from the option when the file has no Axis line.
  ImportOptions o;
  o.axis = "Z";
  CHECK(parse_instrument_text("Target Position (mm),Direction,Run 1 (nm)\n5,Up,1500\n", "z.csv", o)
            .table.column("dz_um")[0] == doctest::Approx(1.5));
}

TEST_CASE("import: every bad CARTO input names its file, line and column") {
  const std::string head = "Axis,X\nTarget Position (mm),Direction,Run 1 (um)\n";
  CHECK(error_of(head + "0,Forward,abc\n") ==
        "f.csv:3:11: column 'Run 1 (um)': 'abc' is not a number");
  CHECK(error_of(head + "0,Sideways,1\n") ==
        "f.csv:3:3: column 'Direction': 'Sideways' is not a direction (Forward/Fwd/+1/Up or "
        "Reverse/Backward/Bwd/-1/Down)");
  CHECK(error_of(head + ",Forward,1\n") ==
        "f.csv:3:1: column 'Target Position (mm)': empty: every row needs its target");
  CHECK(error_of(head + "0,Forward,1,2\n") ==
        "f.csv:3:13: 4 fields, the header (line 2) has 3 (decimal commas in a comma-separated "
        "file split every number: export with ';' or a tab between the fields, or with a "
        "decimal point)");
  CHECK(parse_instrument_text(head + "0,Forward,1,\n", "f.csv").table.rows() == 1);  // trailing ,
  CHECK(error_of(head) == "f.csv:2: no data rows after the header");
  CHECK(error_of("Axis,X\nTarget Position (mm),Direction,Run 1 (psi)\n0,Forward,1\n")
            .rfind("f.csv:2:32: column 'Run 1 (psi)': unit 'psi' (lengths: mm", 0) == 0);
  CHECK(error_of("Axis,X\nTarget Position (mm),Direction,Run 1 (arcsec)\n0,Forward,1\n") ==
        "f.csv:2:32: column 'Run 1 (arcsec)': unit 'arcsec' is an angle but the axis is linear "
        "(in um)");
  CHECK(error_of("Axis,X\nTarget Position (mm),Direction,Run 1 (um),Load (kg)\n0,Forward,1,2\n")
            .rfind("f.csv:2:43: column 'Load (kg)': not a column of a CARTO linear export", 0) ==
        0);
  CHECK(error_of("Axis,X\nTarget Position (mm),Direction,Run 1 (um),Run 1 (um)\n0,Forward,1,2\n") ==
        "f.csv:2:43: duplicate column 'Run 1 (um)'");
  CHECK(error_of("Target Position (mm),Direction,Run 1 (um)\n0,Forward,1\n") ==
        "f.csv:1: CARTO: the file does not name its axis (no 'Axis' line before the table): "
        "give it with --axis");
  CHECK(error_of("Axis,X\nAxis,Y\nTarget Position (mm),Direction,Run 1 (um)\n0,Forward,1\n") ==
        "f.csv:2:1: header key 'axis' given twice (first at line 1)");
  CHECK(error_of("Axis,Q9\nTarget Position (mm),Direction,Run 1 (um)\n0,Forward,1\n") ==
        "f.csv:1: axis: 'Q9' names no axis letter (X, Y, Z, A, B, C ...)");
  CHECK(error_of("Axis,X\nTarget Position (mm),Run 1 (um)\n0,1\n") ==
        "f.csv:2: no Direction column: each row needs its approach direction (Forward or "
        "Reverse)");
  CHECK(error_of("Axis,X\nAir Compensation,maybe\nTarget Position (mm),Direction,Run 1 (um)\n") ==
        "f.csv:2:18: 'Air Compensation': 'maybe' (expected on/applied/automatic/manual or "
        "off/none)");
  CHECK(error_of("Axis,X\nTarget Position (mm),Direction,Run 1 (um)\n0,\"Forward,1\n") ==
        "f.csv:3:3: unterminated quote");
  ImportOptions o;
  o.axis = "Y";
  CHECK(error_of("Axis,X\nTarget Position (mm),Direction,Run 1 (um)\n0,Forward,1\n", o) ==
        "invalid_argument: --axis Y: f.csv measures axis X (line 1)");
  // Unknown columns are skipped with a warning when allowed.
  o = {};
  o.read.allow_unknown = true;
  const ImportResult skipped = parse_instrument_text(
      "Axis,X\nTarget Position (mm),Direction,Load (kg),Run 1 (um)\n0,Forward,5,1\n", "f.csv", o);
  CHECK(skipped.table.warnings ==
        std::vector<std::string>{"f.csv:2:32: unknown column 'Load (kg)' (skipped)"});
  CHECK(skipped.table.column("dx_um")[0] == 1);
}

TEST_CASE("import: every bad generic wide input names its file, line and column") {
  const std::string keys = "# format: wide\n# axis: X\n";
  CHECK(error_of(keys + "X,dir,cycle,dx_um@1\n0,1,1,2\n") ==
        "f.csv:3:7: a wide file gives the cycle in the column names (dx_um@1, dx_um@2 ...), not "
        "in a column 'cycle'");
  CHECK(error_of(keys + "X,dir,dx_um\n0,1,2\n") ==
        "f.csv:3:7: deviation column 'dx_um' without its cycle ('dx_um@1' ...)");
  CHECK(error_of(keys + "X,dir,dx_um@0\n0,1,2\n") ==
        "f.csv:3:7: column 'dx_um@0': the cycle after '@' must be a whole number >= 1");
  CHECK(error_of(keys + "X,dir,dir@1,dx_um@1\n0,1,1,2\n") ==
        "f.csv:3:7: column 'dir@1': 'dir' is not a deviation, time, temperature or covariate "
        "column");
  CHECK(error_of(keys + "X,dir,T_air@1\n0,1,20\n") ==
        "f.csv:3: no per-cycle deviation column (dx_um@1, dx_um@2 ...)");
  CHECK(error_of(keys + "X,dir,dx_um@1\n0,1,abc\n") ==
        "f.csv:4:5: column 'dx_um@1': 'abc' is not a number");
  CHECK(
      error_of(keys + "X,dir,load,dx_um@1\n0,1,3,2\n").rfind("f.csv:3: unknown column 'load'", 0) ==
      0);
}

TEST_CASE("import: the tidy writer reads back as the same table") {
  for (const char* text : {kCartoSmall, kWideSmall}) {
    const ImportResult r = parse_instrument_text(text, "in.csv");
    const std::string csv = measurement_csv(r.table, import_comments("in.csv", r));
    const MeasurementTable back = parse_measurements(csv, "back.csv");
    CHECK(back.columns == r.table.columns);
    CHECK(back.header_keys == r.table.header_keys);
    REQUIRE(back.rows() == r.table.rows());
    for (const auto& c : back.columns)
      for (std::size_t k = 0; k < back.rows(); ++k) {
        const double a = back.column(c)[k], b = r.table.column(c)[k];
        CHECK(((std::isnan(a) && std::isnan(b)) || a == b));
      }
    CHECK(csv.find("# written by weilgen import from in.csv") != std::string::npos);
  }
}

TEST_CASE("import CLI: prints the tidy CSV, writes --out atomically, refuses bad input") {
  const auto dir = test::fresh_dir("import_cli");
  const std::string carto = (dir / "carto.csv").string(), out = (dir / "tidy.csv").string();
  write_file_atomically(carto, kCartoSmall);
  test::Run r = run(cli("import " + carto));
  CHECK(r.status == 0);
  CHECK(
      r.out.find(
          "X,dir,T_air,p_air_Pa,RH_air_pct,T_material,cycle,dx_um\n0,1,20.1,101320,45,20,1,1\n") !=
      std::string::npos);
  r = run(cli("import " + carto + " --out " + out));
  CHECK(r.status == 0);
  CHECK(r.out.find("CARTO wide CSV, 6 rows -> 18 observations (axis X)") != std::string::npos);
  CHECK(test::read_text(out).find("# machine: Test rig 7\n") == 0);
  // iso230-2 reads the CARTO file itself, and the tidy file it became, to the same JSON figures.
  const std::string j1 = (dir / "a.json").string(), j2 = (dir / "b.json").string();
  r = run(cli("iso230-2 " + carto + " --json " + j1));
  CHECK(r.status == 0);
  CHECK(r.out.find("CARTO wide CSV") != std::string::npos);
  CHECK(run(cli("iso230-2 " + out + " --json " + j2)).status == 0);
  const json a = json::parse(test::read_text(j1)), b = json::parse(test::read_text(j2));
  CHECK(a["A_um"] == b["A_um"]);
  CHECK(a["drift_eliminated"]["R_um"] == b["drift_eliminated"]["R_um"]);
  CHECK(a["source_format"] == "carto");
  CHECK(b["source_format"] == "tidy");
  CHECK(a["metadata"]["machine"] == "Test rig 7");
  // Bad input: exit 3 with the location, the existing output untouched.
  const std::string bad = (dir / "bad.csv").string();
  write_file_atomically(bad, "Axis,X\nTarget Position (mm),Direction,Run 1 (um)\n0,Forward,x1\n");
  write_file_atomically(out, "keep me\n");
  r = run(cli("import " + bad + " --out " + out));
  CHECK(r.status == 3);
  CHECK(r.out.find("bad.csv:3:11: column 'Run 1 (um)': 'x1' is not a number") != std::string::npos);
  CHECK(test::read_text(out) == "keep me\n");
  // Bad flags: exit 2.
  CHECK(run(cli("import " + carto + " --format rtl")).status == 2);
  CHECK(run(cli("import " + carto + " --out " + carto)).status == 2);
  CHECK(run(cli("import " + carto + " --axis Y")).status == 2);
  CHECK(run(cli("import")).status == 2);
}

TEST_CASE("import slips: a leading 'Target No.' column, a title line, runs without a unit") {
  // A CARTO export numbering its targets first: found, the number checked and not carried.
  const std::string numbered =
      "Renishaw XL-80 linear measurement\nAxis,X\n"
      "Target No.,Target Position (mm),Direction,Run 1 (um),Run 2 (um)\n"
      "1,0,Forward,1,2\n2,100,Forward,3,4\n2,100,Reverse,5,6\n1,0,Reverse,7,8\n";
  CHECK(detect_instrument_format(numbered) == InstrumentFormat::Carto);
  const ImportResult r = parse_instrument_text(numbered, "n.csv");
  CHECK(r.table.columns == std::vector<std::string>{"X", "dir", "cycle", "dx_um"});
  CHECK(r.table.rows() == 8);
  CHECK(r.table.column("dx_um")[7] == 8);
  CHECK(r.mapping[0] == "'Target No.' -> (the target's number: checked, not carried)");
  CHECK(error_of("Axis,X\nTarget No.,Target Position (mm),Direction,Run 1 (um)\n"
                 "one,0,Forward,1\n") ==
        "f.csv:3:1: column 'Target No.': 'one' is not a whole number");
  CHECK(
      error_of("Axis,X\nTarget Position (mm),Target (mm),Direction,Run 1 (um)\n0,0,Forward,1\n") ==
      "f.csv:2:22: two target columns: give one");
  // An export whose table is not recognised: the tidy reader's complaint about the title line
  // carries the hint instead of misleading alone.
  const std::string hidden =
      "Renishaw XL-80 linear measurement\nAxis,X\nPosition,Direction,Run 1 (um)\n0,Forward,1\n";
  const std::string e = error_of(hidden);
  CHECK(e.rfind("f.csv:1: unknown column 'Renishaw XL-80 linear measurement'", 0) == 0);
  CHECK(e.find("an instrument export whose table was not found? Its header row needs a target "
               "column such as 'Target Position (mm)'") != std::string::npos);
  // Runs without a unit are refused where the header says nothing, read in the 'Units' line's
  // unit otherwise.
  CHECK(error_of("Axis,X\nTarget Position (mm),Direction,Run 1\n0,Forward,1\n") ==
        "f.csv:2:32: column 'Run 1': no unit: the deviations could be in um, mm or nm; write it "
        "in the header ('Run 1 (um)') or give a 'Units,um' line before the table");
  const ImportResult mm = parse_instrument_text(
      "Axis,X\nUnits,mm\nTarget Position (mm),Direction,Run 1\n0,Forward,0.0012\n", "f.csv");
  CHECK(mm.table.column("dx_um")[0] == doctest::Approx(1.2).epsilon(1e-12));
  CHECK(mm.mapping[2] == "'Run 1' -> dx_um of cycle 1 (um, x 1000)");
}

TEST_CASE("import slips: a wide file's tidy output reads back, a degF sensor is named") {
  // The tidy file an import writes keeps no '# format: wide' key: iso230-2 reads it as tidy.
  const ImportResult w = parse_instrument_text(kWideSmall, "w.csv");
  CHECK(w.table.header_keys.count("format") == 0);
  const auto dir = test::fresh_dir("import_wide_cli");
  const std::string wide = (dir / "wide.csv").string(), out = (dir / "tidy.csv").string();
  write_file_atomically(wide, kWideSmall);
  REQUIRE(run(cli("import " + wide + " --out " + out)).status == 0);
  CHECK(test::read_text(out).find("# format") == std::string::npos);
  const test::Run iso = run(cli("iso230-2 " + out));
  CHECK(iso.status == 0);
  CHECK(iso.out.find("bidirectional accuracy                     14.000") != std::string::npos);

  // Three material sensors, the third labelled degF but recording degC (23 read as -5 degC):
  // the reading is named with its header cell, in the study and on the CLI's stderr.
  const std::string degf =
      "Axis,X\nMaterial Compensation,Off\nMaterial Expansion Coefficient (ppm/K),11.7\n"
      "Target Position (mm),Direction,Run 1 (um),Run 2 (um),Material Temperature 1 (degC),"
      "Material Temperature 2 (degC),Material Temperature 3 (degF)\n"
      "0,Forward,1,2,23.0,23.1,23\n100,Forward,3,4,23.0,23.1,23\n"
      "100,Reverse,5,6,23.0,23.1,23\n0,Reverse,7,8,23.0,23.1,23\n";
  const Iso230_2StudyResult s = study(parse_instrument_text(degf, "f.csv").table);
  REQUIRE(s.normalisation.warnings.size() == 1);
  CHECK(s.normalisation.warnings[0] ==
        "f.csv:4:114: material sensor 'T_material_3' reads -5.0 degC on average beside 23.0 degC, "
        "the median of the material sensors: check its unit (degF read as degC?); it pulls the "
        "mean used for the correction");
  const std::string degf_file = (dir / "degf.csv").string(), js = (dir / "degf.json").string();
  write_file_atomically(degf_file, degf);
  const test::Run r = run(cli("iso230-2 " + degf_file + " --json " + js));
  CHECK(r.status == 0);
  CHECK(r.out.find("degf.csv:4:114: material sensor 'T_material_3' reads -5.0 degC") !=
        std::string::npos);
  CHECK(json::parse(test::read_text(js))["normalisation"]["warnings"].size() == 1);
  // Two sensors that disagree are both named; one tidy sensor far from 20 degC is flagged too.
  const Iso230_2StudyResult two = study(parse_measurements(
      "# axis: X\nX,dir,cycle,dx_um,T_material_1,T_material_2\n0,1,1,1,20,30\n0,1,2,1,20,30\n"
      "0,-1,1,1,20,30\n0,-1,2,1,20,30\n",
      "t.csv"));
  REQUIRE(two.normalisation.warnings.size() == 1);
  CHECK(two.normalisation.warnings[0].rfind(
            "t.csv:2:32: material sensors 'T_material_1' and 'T_material_2' differ by 10.0 K", 0) ==
        0);
  const Iso230_2StudyResult hot = study(parse_measurements(
      "# axis: X\nX,dir,cycle,dx_um,T_material\n0,1,1,1,73\n0,1,2,1,73\n0,-1,1,1,73\n"
      "0,-1,2,1,73\n",
      "h.csv"));
  REQUIRE(hot.normalisation.warnings.size() == 1);
  CHECK(hot.normalisation.warnings[0] ==
        "h.csv:2:19: the material temperature reads 73.0 degC on average, far from a test's 20 "
        "degC: check the unit");
}

TEST_CASE("import: LaserXL-style 'Key: Value' lines and the compensation states") {
  const std::string text =
      "Laser measurement: linear, X axis (a title with a colon)\nAxis: X\n"
      "Material Compensation: On\nEnvironmental Compensation: Automatic\n"
      "Expansion Coefficient (ppm/K): 11.5\n"
      "Target Position (mm),Direction,Run 1 (um),Run 2 (um)\n"
      "0,Forward,1,2\n100,Forward,3,4\n100,Reverse,5,6\n0,Reverse,7,8\n";
  const ImportResult r = parse_instrument_text(text, "xl.csv");
  CHECK(r.table.header_keys.at("axis") == "X");
  CHECK(r.table.header_keys.at("material_compensation") == "instrument");
  CHECK(r.table.header_keys.at("air_compensation") == "instrument");
  CHECK(r.table.header_keys.at("expansion_ppm_per_K") == "11.5");
  CHECK(r.table.header_key_lines.at("material_compensation") == 3);
  CHECK(r.table.header_keys.count("laser_measurement") == 0);  // the title is no key
  CHECK(error_of("Axis,X\nMaterial Compensation,sometimes\n"
                 "Target Position (mm),Direction,Run 1 (um)\n0,Forward,1\n") ==
        "f.csv:2:23: 'Material Compensation': 'sometimes' (expected on/applied/automatic/manual "
        "or off/none)");
}
