// The measurement CSV reader (weilgen/measure/measurement_csv.hpp, docs/data-format.md): every
// column role, comments and header keys, CRLF, and each kind of bad input with its exact
// file:line:column.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "test_support.hpp"
#include "weilgen/measure/measurement_csv.hpp"

using namespace weilgen;

namespace {

// The InputError message of parsing `text` as "data.csv" (fails the test when it parses).
std::string error_of(const std::string& text, const ReadOptions& o = {}) {
  try {
    parse_measurements(text, "data.csv", o);
  } catch (const InputError& e) {
    return e.what();
  }
  FAIL("no InputError for:\n" << text);
  return "";
}

}  // namespace

TEST_CASE("measurement csv: every column role is classified with its unit and axis") {
  const ReadOptions o;
  struct Case {
    const char* name;
    ColumnRole role;
    const char* unit;
    const char* axis;
  };
  const Case cases[] = {{"X", ColumnRole::Coordinate, "mm", ""},
                        {"Z", ColumnRole::Coordinate, "mm", ""},
                        {"A", ColumnRole::Coordinate, "deg", ""},
                        {"C", ColumnRole::Coordinate, "deg", ""},
                        {"t_s", ColumnRole::Time, "s", ""},
                        {"dir", ColumnRole::Direction, "", ""},
                        {"dir_X", ColumnRole::Direction, "", "X"},
                        {"dir_C", ColumnRole::Direction, "", "C"},
                        {"cycle", ColumnRole::Cycle, "", ""},
                        {"T_spindle", ColumnRole::Temperature, "degC", ""},
                        {"T_air_2", ColumnRole::Temperature, "degC", ""},
                        {"rpm", ColumnRole::Covariate, "1/min", ""},
                        {"feed_mm_min", ColumnRole::Covariate, "mm/min", ""},
                        {"cov_load", ColumnRole::Covariate, "", ""},
                        {"dx_um", ColumnRole::Deviation, "um", ""},
                        {"dy_um", ColumnRole::Deviation, "um", ""},
                        {"dz_um", ColumnRole::Deviation, "um", ""},
                        {"da_urad", ColumnRole::Deviation, "urad", ""},
                        {"db_urad", ColumnRole::Deviation, "urad", ""},
                        {"dc_urad", ColumnRole::Deviation, "urad", ""},
                        {"angle_deg", ColumnRole::Angle, "deg", ""},
                        {"dr_um", ColumnRole::Radial, "um", ""},
                        {"x", ColumnRole::Unknown, "", ""},
                        {"XY", ColumnRole::Unknown, "", ""},
                        {"dx_mm", ColumnRole::Unknown, "", ""},
                        {"T_", ColumnRole::Unknown, "", ""},
                        {"cov_", ColumnRole::Unknown, "", ""},
                        {"dir_x", ColumnRole::Unknown, "", ""},
                        {"load", ColumnRole::Unknown, "", ""}};
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const ColumnInfo info = classify_column(c.name, o);
    CHECK(info.name == c.name);
    CHECK(info.role == c.role);
    CHECK(info.unit == c.unit);
    CHECK(info.axis == c.axis);
  }
  // The machine's coordinates restrict the coordinate names; `expected` adds covariates.
  ReadOptions m;
  m.coordinates = {"X", "Y", "Z", "A", "C"};
  m.expected = {"load", "E_YY_um"};
  CHECK(classify_column("B", m).role == ColumnRole::Unknown);
  CHECK(classify_column("dir_B", m).role == ColumnRole::Unknown);
  CHECK(classify_column("A", m).role == ColumnRole::Coordinate);
  CHECK(classify_column("load", m).role == ColumnRole::Covariate);
  CHECK(classify_column("E_YY_um", m).role == ColumnRole::Covariate);
  CHECK(classify_column("dx_um", m).role == ColumnRole::Deviation);  // roles win over expected
  CHECK(std::string(to_string(ColumnRole::Radial)) == "radial");
}

TEST_CASE("measurement csv: comments, header keys, CRLF, blanks, quoted names, empty cells") {
  const std::string text =
      "\xEF\xBB\xBF# ballbar test, 2024-05-02\r\n"
      "# plane: XY\r\n"
      "#centre:  X=0, Y=0, Z=-150 \r\n"
      "# radius: 150 mm\r\n"
      "# a comment: with spaces in the key is just a comment\r\n"
      "\r\n"
      "\"X\", Y ,t_s,dir_X,cycle,T_spindle,rpm,dx_um,dy_um,angle_deg,dr_um\r\n"
      "# a comment between rows\r\n"
      "1.5,-2,0,1,1,21.5,1000,0.5,,0,1.25\r\n"
      "   \r\n"
      "2.5e1, -2 , 0.5 ,-1,2,21.6,1000,-1.5e-1,3,90,-0.5\r\n"
      "# trailing comment: not a key after the header\r\n";
  const MeasurementTable t = parse_measurements(text, "bb.csv");
  CHECK(t.file == "bb.csv");
  CHECK(t.columns == std::vector<std::string>{"X", "Y", "t_s", "dir_X", "cycle", "T_spindle", "rpm",
                                              "dx_um", "dy_um", "angle_deg", "dr_um"});
  CHECK(t.header_line == 7);
  CHECK(t.lines == std::vector<int>{9, 11});
  CHECK(t.rows() == 2);
  CHECK(t.header_keys.size() == 3);
  CHECK(t.header_keys.at("plane") == "XY");
  CHECK(t.header_keys.at("centre") == "X=0, Y=0, Z=-150");
  CHECK(t.header_key("radius") == "150 mm");
  CHECK(t.header_key("feed", "ccw") == "ccw");
  CHECK(t.header_key_lines.at("plane") == 2);
  CHECK(t.column("X") == std::vector<double>{1.5, 25.0});
  CHECK(t.column("Y") == std::vector<double>{-2, -2});
  CHECK(t.column("dir_X") == std::vector<double>{1, -1});
  CHECK(t.column("dx_um")[1] == -0.15);
  CHECK(std::isnan(t.column("dy_um")[0]));  // empty = not measured
  CHECK(t.column("dy_um")[1] == 3);
  CHECK(t.column("dr_um") == std::vector<double>{1.25, -0.5});
  CHECK(t.has("rpm"));
  CHECK(!t.has("dz_um"));
  CHECK(t.info_of("T_spindle").role == ColumnRole::Temperature);
  CHECK(t.columns_with(ColumnRole::Coordinate) == std::vector<std::string>{"X", "Y"});
  CHECK(t.columns_with(ColumnRole::Deviation) == std::vector<std::string>{"dx_um", "dy_um"});
  CHECK(t.warnings.empty());
}

TEST_CASE("measurement csv: a missing column names the file and lists the columns") {
  const MeasurementTable t = parse_measurements("X,dir,cycle,dx_um\n0,1,1,2\n", "d.csv");
  try {
    t.column("dy_um");
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == "d.csv: missing column 'dy_um' (columns: X, dir, cycle, dx_um)");
  }
}

TEST_CASE("measurement csv: unknown columns are an error listing them, or warnings on request") {
  const std::string text = "X,dx_um,load,speed\n0,1,2,3\n";
  const std::string msg = error_of(text);
  CHECK(msg.rfind("data.csv:1: unknown columns 'load', 'speed' (known: coordinates", 0) == 0);
  CHECK(msg.find("cov_<name>") != std::string::npos);
  CHECK(error_of("X,Temp\n1,2\n").rfind("data.csv:1: unknown column 'Temp' (known:", 0) == 0);
  ReadOptions o;
  o.allow_unknown = true;
  const MeasurementTable t = parse_measurements(text, "data.csv", o);
  REQUIRE(t.warnings.size() == 2);
  CHECK(t.warnings[0] == "data.csv:1:9: unknown column 'load' (kept, not interpreted)");
  CHECK(t.warnings[1] == "data.csv:1:14: unknown column 'speed' (kept, not interpreted)");
  CHECK(t.column("speed") == std::vector<double>{3});
  CHECK(t.info_of("load").role == ColumnRole::Unknown);
  o.allow_unknown = false;
  o.expected = {"load", "speed"};
  CHECK(parse_measurements(text, "data.csv", o).info_of("speed").role == ColumnRole::Covariate);
}

TEST_CASE("measurement csv: each bad input names its line and column") {
  // Not a number: line 3, the cell starts at character 7.
  CHECK(error_of("# c\nX,dir,dx_um\n0,1,  abc\n") ==
        "data.csv:3:7: column 'dx_um': 'abc' is not a number");
  CHECK(error_of("X,dx_um\n0,1\n\n0,1.2.3\n") ==
        "data.csv:4:3: column 'dx_um': '1.2.3' is not a number");
  // NaN and infinities are rejected: an empty cell is the only "not measured".
  CHECK(error_of("X,dx_um\n0,nan\n") == "data.csv:2:3: column 'dx_um': 'nan' is not a number");
  CHECK(error_of("X,dx_um\n0,-inf\n") == "data.csv:2:3: column 'dx_um': '-inf' is not a number");
  CHECK(error_of("X,dx_um\n0,1e999\n") == "data.csv:2:3: column 'dx_um': '1e999' is out of range");
  CHECK(error_of("X,dx_um\n0x10,1\n") == "data.csv:2:1: column 'X': '0x10' is not a number");
  // Wrong field count.
  CHECK(error_of("X,dir,dx_um\n0,1,2\n0,1\n") == "data.csv:3: 2 fields, the header (line 1) has 3");
  CHECK(error_of("X,dir,dx_um\n0,1,2,\n") == "data.csv:2: 4 fields, the header (line 1) has 3");
  // Direction and cycle.
  CHECK(error_of("X,dir,dx_um\n0,2,1\n") == "data.csv:2:3: column 'dir': '2' must be +1 or -1");
  CHECK(error_of("X,dir_X,dx_um\n0,0,1\n") == "data.csv:2:3: column 'dir_X': '0' must be +1 or -1");
  CHECK(error_of("X,cycle,dx_um\n0,1.5,1\n") ==
        "data.csv:2:3: column 'cycle': '1.5' is not an integer");
  // Header problems.
  CHECK(error_of("X,dx_um,X\n0,1,2\n") ==
        "data.csv:1:9: duplicate column 'X' (also header field 1)");
  CHECK(error_of("X,\"X\"\n0,1\n") == "data.csv:1:3: duplicate column 'X' (also header field 1)");
  CHECK(error_of("X,,dx_um\n0,1,2\n") == "data.csv:1:3: empty column name (header field 2)");
  CHECK(error_of("# axis: X\n# axis: Y\nX,dx_um\n0,1\n") ==
        "data.csv:2:3: header key 'axis' given twice (first at line 1)");
  // Empty file, only comments, no data rows.
  CHECK(error_of("") == "data.csv: empty file");
  CHECK(error_of("# only: comments\n\n") ==
        "data.csv: no header row (only comments and blank lines)");
  CHECK(error_of("# c\nX,dx_um\n# no rows\n") == "data.csv:2: no data rows after the header");
}

TEST_CASE("measurement csv: read_measurements reads a file and names a missing one") {
  const auto dir = test::fresh_dir("measurement_csv");
  const std::string path = (dir / "m.csv").string();
  {
    std::ofstream f(path);
    f << "X,dir,cycle,dx_um\n0,1,1,2.5\n";
  }
  const MeasurementTable t = read_measurements(path);
  CHECK(t.file == path);
  CHECK(t.column("dx_um") == std::vector<double>{2.5});
  try {
    read_measurements((dir / "nope.csv").string());
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) ==
          (dir / "nope.csv").string() + ": cannot read the data file: no such file");
  }
}
