// Issue 16: hostile input through the CLI. One test per row of the table (the reproducer
// first, then what must hold: the exit code, a message naming the flag or file:line:column, and
// nothing written or destroyed), and the checks behind them (numeric ranges, C++ names, the
// algebra size, the model cache, atomic writes). The broad replay of hostile flags of every verb
// is tests/robustness/hostile_cli.py (CTest hostile_cli); docs/robustness.md.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/expr.hpp"
#include "weilgen/base/range.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/algebra_size.hpp"
#include "weilgen/machine/cxx_names.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/model/model_loader.hpp"

using namespace weilgen;
using test::cli;
using test::run;
using test::Run;
namespace fs = std::filesystem;

namespace {

// Every file under `dir` (recursively) with its contents: a refused command must leave this
// unchanged (no output, no temporary file, no input replaced).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> s;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    s[e.path().string()] = e.is_regular_file() ? test::read_text(e.path().string()) : "<dir>";
  return s;
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// Runs `args` in `dir` (cd), expects exit `status`, every word in the output, and `dir` unchanged.
Run refused(const fs::path& dir, const std::string& args, int status,
            const std::vector<std::string>& words) {
  const auto before = snapshot(dir);
  const Run r = run("cd '" + dir.string() + "' && " + cli(args));
  INFO("weilgen " << args << "\n" << r.out);
  CHECK(r.status == status);
  for (const auto& w : words) {
    INFO("expected: " << w);
    CHECK(r.out.find(w) != std::string::npos);
  }
  CHECK(snapshot(dir) == before);
  return r;
}

const char* kPose = " --at X=0,Y=0,Z=600 --quiet";

}  // namespace

TEST_CASE("robustness #1: --bootstrap -1 is refused naming the flag and its range (was exit 139)") {
  const auto dir = test::fresh_dir("robust_1");
  write(dir / "keep.json", "previous");
  refused(dir,
          std::string("sensitivity gantry_grinder") + kPose + " --bootstrap -1 --json keep.json", 2,
          {"--bootstrap: '-1' is out of range (allowed: a whole number from 0 to 1000000)"});
}

TEST_CASE("robustness #2: numeric flags range-checked and memory estimated before allocation") {
  const auto dir = test::fresh_dir("robust_2");
  write(dir / "keep.json", "previous");
  const std::string s = std::string("sensitivity gantry_grinder") + kPose + " --json keep.json";
  refused(dir, s + " --threads -1", 2, {"--threads: '-1'", "a whole number from 0 to 1024"});
  refused(dir, s + " --threads 4294967295", 2, {"--threads", "from 0 to 1024"});
  refused(dir, s + " --samples -5", 2, {"--samples: '-5'", "from 2 to 4294967295"});
  refused(dir, s + " --bootstrap 100000000000", 2, {"--bootstrap", "from 0 to 1000000"});
  refused(dir, s + " --samples 12abc", 2, {"--samples: '12abc' is not a number"});
  refused(dir, s + " --confidence nan", 2, {"--confidence: 'nan' is not a number", "(0, 1)"});
  // In range, but 4e9 samples x 21 errors need terabytes: refused before any allocation.
  const Run r = refused(dir, s + " --samples 4000000000", 2,
                        {"--samples 4000000000", "memory", "lower --samples"});
  CHECK(r.out.find("bad_alloc") == std::string::npos);
}

TEST_CASE("robustness #3: an output that is an input is refused (canonical paths), every verb") {
  const auto dir = test::fresh_dir("robust_3");
  fs::copy_file(test::machine_path("gantry_grinder"), dir / "m.yaml");
  fs::copy_file(std::string(WEILGEN_SOURCE_DIR) + "/examples/data/iso230_2_small.csv",
                dir / "d.csv");
  fs::copy_file(std::string(WEILGEN_SOURCE_DIR) + "/examples/data/vmc_3axis_points.csv",
                dir / "p.csv");
  fs::copy_file(std::string(WEILGEN_SOURCE_DIR) + "/machines/tolerances/gantry_grinder_tight.yaml",
                dir / "t.yaml");
  fs::create_symlink("m.yaml", dir / "link.yaml");
  const std::string is_input = "is the input";
  refused(dir, std::string("sensitivity m.yaml") + kPose + " --json m.yaml", 2,
          {"--json: 'm.yaml' is the input machine file", "choose another file"});
  refused(dir, std::string("sensitivity m.yaml") + kPose + " --csv ./sub/../m.yaml", 2,
          {"--csv", is_input});
  refused(dir, std::string("sensitivity m.yaml") + kPose + " --json link.yaml", 2,
          {"--json", is_input});
  refused(dir, std::string("sensitivity m.yaml") + kPose + " --json x.json --csv x.json", 2,
          {"--csv: 'x.json' is also the output of --json"});
  refused(dir, "iso230-2 d.csv --json d.csv", 2, {"--json: 'd.csv' is the input data file"});
  refused(dir, "fit-pdge d.csv --plot d.csv", 2, {"--plot", is_input});
  refused(dir, "identify vmc_3axis --data p.csv --emit-params p.csv --quiet", 2,
          {"--emit-params: 'p.csv' is the input --data"});
  refused(dir, "gap vmc_3axis --data p.csv --report p.csv --quiet", 2, {"--report", is_input});
  refused(dir,
          "allocate m.yaml --grid X=0,Y=0,Z=600 --tolerance dx=0.03mm --tolerances t.yaml "
          "--save-tolerances t.yaml --quiet",
          2, {"--save-tolerances: 't.yaml' is the input --tolerances"});
  refused(dir, std::string("reliability m.yaml") + kPose + " --tolerance dx=30um --json .", 2,
          {"--json: '.' is a directory"});
  // generate: a machine file that happens to carry the name of an output.
  fs::copy_file(test::machine_path("two_axis"), dir / "two_axis.md");
  refused(dir, "generate two_axis.md --out .", 2, {"--out: './two_axis.md' is the input"});
}

TEST_CASE("robustness #4: C++ keywords and reserved identifiers are refused by the loader") {
  // One small machine; every name is substituted in turn.
  const auto machine = [](std::string name, std::string param, std::string coord, std::string err) {
    return "weilgen: 1\nname: " + name + "\nparameters:\n  " + param +
           ": {value: 100, unit: mm}\nbodies:\n  base: {}\n  slide:\n    parent: base\n"
           "    joint: {type: prismatic, axis: x, coordinate: " +
           coord + ", unit: mm, range: [0, 500]}\n    errors:\n      " + err +
           ": {effect: translation, direction: x, group: positioning, sigma: 1, "
           "unit: um}\n  tool: {parent: "
           "slide}\ntool: {body: tool, point: [0, 0, " +
           param + "]}\nworkpiece: {body: base}\n";
  };
  CHECK(test::load_error(machine("m", "L", "X", "e_x")) == "");
  const auto expect = [](const std::string& yaml, const std::string& where,
                         const std::string& words) {
    const std::string m = test::load_error(yaml);
    INFO(m);
    CHECK(m.rfind(where + ": ", 0) == 0);
    CHECK(m.find(words) != std::string::npos);
  };
  expect(machine("int", "L", "X", "e"), "bad.yaml:2:7", "machine name 'int' is a C++ keyword");
  expect(machine("m", "delete", "X", "e"), "bad.yaml:4:3",
         "parameter name 'delete' is a C++ keyword");
  expect(machine("m", "L", "and", "e"), "bad.yaml:9:51", "coordinate 'and' is a C++ keyword");
  expect(machine("m", "L", "X", "_Err"), "bad.yaml:11:7", "reserved for the C++ implementation");
  expect(machine("m", "L", "X", "e__x"), "bad.yaml:11:7", "reserved for the C++ implementation");
  expect(machine("m", "_tmp0", "X", "e"), "bad.yaml:4:3", "starts with '_'");
  expect(machine("m", "L", "errno", "e"), "bad.yaml:9:51", "is a macro");
  expect(machine("m", "M_PI", "X", "e"), "bad.yaml:4:3", "is a macro");
  expect(machine("std", "L", "X", "e"), "bad.yaml:2:7", "is a name of the generated code");
  expect(machine("m", "L", "X", "errors"), "bad.yaml:11:7", "is a name of the generated code");
  expect(machine("m", "Scalar", "X", "e"), "bad.yaml:4:3", "is a name of the generated code");
  expect(machine("m", "kNumAxes", "X", "e"), "bad.yaml:4:3", "is a name of the generated code");
  // cos_<coordinate> and sin_<coordinate> are the generated code's.
  expect(machine("m", "cos_X", "X", "e"), "bad.yaml:9:51", "'cos_X' is already the name of");
  // Through the CLI: exit 3 with file:line:column, and no compiler errors.
  const auto dir = test::fresh_dir("robust_4");
  write(dir / "int.yaml", machine("int", "L", "X", "e"));
  const Run r = refused(dir, "sensitivity int.yaml --at X=1 --method local", 3,
                        {"int.yaml:2:7: name: machine name 'int' is a C++ keyword"});
  CHECK(r.out.find("error:") == std::string::npos);  // no compiler output
  // The rules themselves.
  CHECK(cxx_name_problem("E_XX") == "");
  CHECK(cxx_name_problem("tool_length") == "");
  CHECK(cxx_name_problem("kappa") == "");
  CHECK(cxx_name_problem("co_await") != "");
  CHECK(cxx_name_problem("NULL") != "");
  CHECK(cxx_name_problem("linux") != "");
}

TEST_CASE("robustness #5: generate pipe_cutter --order 2 is byte-identical in five processes") {
  // Five processes at once (GiNaC's hash order differs between runs; commit 5b21ae2 made every
  // printed sign and term order canonical).
  const auto dir = test::fresh_dir("robust_5");
  std::string cmd;
  for (int i = 0; i < 5; ++i)
    cmd += cli("generate pipe_cutter --order 2 --out " + (dir / std::to_string(i)).string()) +
           " > /dev/null & ";
  REQUIRE(run(cmd + "wait").status == 0);
  const std::string hpp = test::read_text((dir / "0" / "pipe_cutter_o2.hpp").string());
  const std::string md = test::read_text((dir / "0" / "pipe_cutter_o2.md").string());
  REQUIRE(hpp.size() > 1000);
  REQUIRE(md.size() > 1000);
  for (int i = 1; i < 5; ++i) {
    CAPTURE(i);
    CHECK(test::read_text((dir / std::to_string(i) / "pipe_cutter_o2.hpp").string()) == hpp);
    CHECK(test::read_text((dir / std::to_string(i) / "pipe_cutter_o2.md").string()) == md);
  }
}

namespace {

// A shared object whose constructor writes `marker`: a planted cache entry.
std::string plant(const fs::path& so, const fs::path& marker) {
  const fs::path src = so.string() + ".cpp";
  write(src,
        "#include <cstdio>\n__attribute__((constructor)) static void planted() {\n"
        "  if (FILE* f = std::fopen(\"" +
            marker.string() + "\", \"w\")) std::fclose(f);\n}\n");
  return std::string(WEILGEN_CXX) + " -shared -fPIC -o '" + so.string() + "' '" + src.string() +
         "'";
}

// The cache entry name of the copy `name.yaml` of two_axis with a comment (not built in).
struct CachedMachine {
  fs::path dir, machine, cache;
  std::string args;
};

CachedMachine cached_machine(const std::string& test_name) {
  CachedMachine c;
  c.dir = test::fresh_dir(test_name);
  c.machine = c.dir / "two_axis_copy.yaml";
  write(c.machine, test::read_text(test::machine_path("two_axis")) + "\n# " + test_name + "\n");
  c.cache = c.dir / "cache";
  c.args = "sensitivity " + c.machine.string() + " --at Y=100,A=30 --method local";
  return c;
}

std::string entry_of(const fs::path& cache) {
  for (const auto& e : fs::directory_iterator(cache))
    if (e.path().extension() == ".so") return e.path().string();
  return "";
}

}  // namespace

TEST_CASE("robustness #6: the model cache is checked before any dlopen") {
  CachedMachine c = cached_machine("robust_6");
  const std::string env = "WEILGEN_CACHE_DIR='" + c.cache.string() + "' ";
  // A fresh cache directory is created 0700.
  Run r = run(env + cli(c.args));
  REQUIRE(r.status == 0);
  struct stat st {};
  REQUIRE(::stat(c.cache.c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0700);
  const std::string entry = entry_of(c.cache);
  REQUIRE(!entry.empty());
  REQUIRE(::stat(entry.c_str(), &st) == 0);
  CHECK((st.st_mode & 0077) == 0);
  // Someone else could have written it: refused, and the planted object never runs.
  const fs::path marker = c.dir / "constructor_ran";
  REQUIRE(run(plant(entry, marker)).status == 0);
  ::chmod(entry.c_str(), 0600);
  ::chmod(c.cache.c_str(), 0777);
  r = run(env + cli(c.args));
  CHECK(r.status == 1);
  CHECK(r.out.find("model cache " + c.cache.string() +
                   ": is writable by group or others (mode "
                   "0777)") != std::string::npos);
  CHECK(r.out.find("chmod 700") != std::string::npos);
  CHECK(!fs::exists(marker));
  if (::geteuid() == 0) {  // a directory of another user
    ::chmod(c.cache.c_str(), 0700);
    REQUIRE(::chown(c.cache.c_str(), 65534, 65534) == 0);
    r = run(env + cli(c.args));
    CHECK(r.status == 1);
    CHECK(r.out.find("is owned by uid 65534, not by you") != std::string::npos);
    CHECK(!fs::exists(marker));
    REQUIRE(::chown(c.cache.c_str(), 0, 0) == 0);
  }
  // The planted object in a good directory has no valid trailer: discarded, never loaded.
  ::chmod(c.cache.c_str(), 0700);
  r = run(env + cli(c.args));
  CHECK(r.status == 0);
  CHECK(r.out.find("discarded, it is compiled again") != std::string::npos);
  CHECK(!fs::exists(marker));
  // Without HOME, XDG_CACHE_HOME and WEILGEN_CACHE_DIR: the account's home, never a shared
  // /tmp/weilgen-cache.
  r = run("env -u HOME -u XDG_CACHE_HOME -u WEILGEN_CACHE_DIR " + cli(c.args + " --compiler none"));
  CHECK(r.status == 0);
  const char* home = std::getenv("HOME");
  std::string saved = home ? home : "";
  ::unsetenv("HOME");
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  std::string saved_xdg = xdg ? xdg : "";
  ::unsetenv("XDG_CACHE_HOME");
  const char* wcd = std::getenv("WEILGEN_CACHE_DIR");
  std::string saved_wcd = wcd ? wcd : "";
  ::unsetenv("WEILGEN_CACHE_DIR");
  const std::string d = default_cache_dir();
  if (!saved.empty()) ::setenv("HOME", saved.c_str(), 1);
  if (!saved_xdg.empty()) ::setenv("XDG_CACHE_HOME", saved_xdg.c_str(), 1);
  if (!saved_wcd.empty()) ::setenv("WEILGEN_CACHE_DIR", saved_wcd.c_str(), 1);
  CHECK(d != "/tmp/weilgen-cache");
  CHECK(d.find("weilgen") != std::string::npos);
}

TEST_CASE("robustness #7: a truncated cache entry is discarded and recompiled with a note") {
  CachedMachine c = cached_machine("robust_7");
  const std::string env = "WEILGEN_CACHE_DIR='" + c.cache.string() + "' ";
  REQUIRE(run(env + cli(c.args + " --json " + (c.dir / "a.json").string())).status == 0);
  const std::string entry = entry_of(c.cache);
  REQUIRE(!entry.empty());
  fs::resize_file(entry, fs::file_size(entry) / 2);  // was a bus error inside dlopen
  const Run r = run(env + cli(c.args + " --json " + (c.dir / "b.json").string()));
  INFO(r.out);
  CHECK(r.status == 0);
  CHECK(r.out.find("note: the cached model " + entry) != std::string::npos);
  CHECK(r.out.find("discarded, it is compiled again") != std::string::npos);
  CHECK(r.out.find("compiling model") != std::string::npos);
  CHECK(test::read_text((c.dir / "a.json").string()) ==
        test::read_text((c.dir / "b.json").string()));
  // And the new entry is intact: the next run loads it without a note.
  const Run again = run(env + cli(c.args));
  CHECK(again.status == 0);
  CHECK(again.out.find("note:") == std::string::npos);
  CHECK(again.out.find("compiling") == std::string::npos);
}

TEST_CASE("robustness #8: --order 0 is refused and large orders are estimated before starting") {
  const auto dir = test::fresh_dir("robust_8");
  refused(dir, "generate two_axis --order 0 --out .", 2,
          {"--order: '0' is out of range (allowed: a whole number from 1 to 20)"});
  refused(dir, std::string("sensitivity gantry_grinder") + kPose + " --order 0", 2, {"--order"});
  // Far too large: refused with the estimate, at once.
  refused(dir, "show pipe_cutter --order 9", 2,
          {"--order 9: pipe_cutter at order 9 has 70 errors, up to", "error monomials",
           "choose a lower order"});
  refused(dir, std::string("sensitivity pipe_cutter --order 9 --at X=0"), 2, {"--order 9"});
  // The estimate: C(k + r, r) - 1 monomials of degree 1..r in k errors.
  CHECK(algebra_monomials(70, 1) == 70);
  CHECK(algebra_monomials(70, 2) == 2555);
  CHECK(algebra_monomials(70, 3) == 62195);
  const Description pipe = load_machine_file(test::machine_path("pipe_cutter"));
  CHECK(check_algebra_size(pipe, 2, "--order 2") == "");
  const std::string w = check_algebra_size(pipe, 3, "--order 3");
  CHECK(w.find("warning: pipe_cutter at order 3 has 70 errors, up to 62195 error monomials") == 0);
  const Description five = load_machine_file(test::machine_path("five_axis_ac"));
  CHECK(check_algebra_size(five, 3, "--order 3") == "");  // 15179: tested every run
  // The same limits for a machine file's own order (exit 3, located).
  std::string text = test::read_text(test::machine_path("pipe_cutter"));
  const auto at = text.find("algebra:");
  REQUIRE(at != std::string::npos);
  const std::string bad =
      text.substr(0, at) + "algebra: {order: 0}" + text.substr(text.find('\n', at));
  CHECK(test::load_error(bad).find("order must be a whole number from 1 to 20") !=
        std::string::npos);
  const std::string big =
      text.substr(0, at) + "algebra: {order: 9}" + text.substr(text.find('\n', at));
  CHECK(test::load_error(big).find("order 9: pipe_cutter at order 9 has 70 errors") !=
        std::string::npos);
}

TEST_CASE("robustness #9: a directory, 1e400 and an empty cell, each named where it is") {
  const auto dir = test::fresh_dir("robust_9");
  fs::create_directory(dir / "d.csv");
  fs::create_directory(dir / "m.yaml");
  refused(dir, "iso230-2 d.csv", 3, {"d.csv: cannot read the data file: is a directory"});
  refused(dir, "sensitivity m.yaml --at X=0", 3,
          {"m.yaml: cannot read the machine file: is a directory"});
  refused(dir, "identify vmc_3axis --data d.csv --quiet", 3, {"d.csv", "is a directory"});
  // 1e400 in a machine file: out of range, at its cell.
  std::string text = test::read_text(test::machine_path("two_axis"));
  const std::string from = "range: [0, 500]";
  text.replace(text.find(from), from.size(), "range: [0, 1e400]");
  write(dir / "big.yaml", text);
  const Run r = refused(dir, "show big.yaml", 3, {"out of range"});
  CHECK(r.out.find("big.yaml:") == 0);
  CHECK(r.out.find("malformed") == std::string::npos);
  // An empty cell: its line and column.
  const std::string src = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/";
  std::string pts = test::read_text(src + "vmc_3axis_points.csv");
  const auto header = pts.find("\nX,");
  REQUIRE(header != std::string::npos);
  const auto row = pts.find('\n', header + 1) + 1;  // the first data row
  pts.erase(row, pts.find(',', row) - row);         // its X cell
  write(dir / "p.csv", pts);
  int line = 1;
  for (std::size_t i = 0; i < row; ++i) line += pts[i] == '\n';
  refused(dir, "identify vmc_3axis --data p.csv --quiet", 3,
          {"p.csv:" + std::to_string(line) + ":1: column 'X' is empty"});
  // ISO 230-2: an empty deviation is the missing observation, named at its cell.
  std::string iso = test::read_text(src + "iso230_2_small.csv");
  const std::string row10 = "\n200,-1,1,";
  const auto at = iso.find(row10);
  REQUIRE(at != std::string::npos);
  const auto cell = at + row10.size();
  const auto cell_end = iso.find(',', cell);  // t_s, then dx_um
  const auto eol = iso.find('\n', cell_end + 1);
  iso.erase(cell_end + 1, eol - cell_end - 1);
  write(dir / "e.csv", iso);
  line = 1;
  for (std::size_t i = 0; i <= at; ++i) line += iso[i] == '\n';
  const int column = static_cast<int>(cell_end + 1 - (at + 1)) + 1;
  refused(dir, "iso230-2 e.csv", 3,
          {"e.csv:" + std::to_string(line) + ":" + std::to_string(column) +
           ": the deviation is empty, but it is the observation of target 200 mm, direction"});
}

TEST_CASE("robustness #10: impossible magnitudes, poses outside the travel, another machine") {
  const auto dir = test::fresh_dir("robust_10");
  const std::string pts =
      test::read_text(std::string(WEILGEN_SOURCE_DIR) + "/examples/data/vmc_3axis_points.csv");
  const auto header = pts.find("\nX,");
  const auto row = pts.find('\n', header + 1) + 1;
  int line = 1;
  for (std::size_t i = 0; i < row; ++i) line += pts[i] == '\n';
  const std::string head = pts.substr(header + 1, pts.find('\n', header + 1) - header - 1);
  INFO(head);
  // The header is X,Y,Z,...,dx_um,...: replace the first row by one of our own.
  const auto with_row = [&](const std::string& r) {
    return pts.substr(0, row) + r + pts.substr(pts.find('\n', row));
  };
  std::vector<std::string> cols = split(head, ',');
  std::string big, far;
  for (std::size_t c = 0; c < cols.size(); ++c) {
    const std::string v = cols[c] == "dx_um" ? "1e300" : cols[c] == "Z" ? "-100" : "0";
    big += (c ? "," : "") + v;
    far += (c ? "," : "") + std::string(cols[c] == "X" ? "99999" : cols[c] == "Z" ? "-100" : "0");
  }
  write(dir / "big.csv", with_row(big));
  refused(dir, "identify vmc_3axis --data big.csv --quiet", 3,
          {"big.csv:" + std::to_string(line) + ":", "column 'dx_um': 1e+300 um is impossible"});
  // Outside the stroke: a warning with the cell, the run goes on.
  write(dir / "far.csv", with_row(far));
  const Run r =
      run("cd '" + dir.string() + "' && " + cli("identify vmc_3axis --data far.csv --quiet"));
  CHECK(r.status == 0);
  CHECK(r.out.find("far.csv:" + std::to_string(line) +
                   ":1: warning: column 'X': 99999 mm is "
                   "outside the travel range") != std::string::npos);
  // Recorded on another machine.
  write(dir / "other.csv", pts);  // '# machine: vmc_3axis'
  refused(dir, "identify gantry_grinder --data other.csv --quiet", 3,
          {"other.csv:4: '# machine: vmc_3axis', but the machine given is gantry_grinder"});
}

TEST_CASE("robustness: generate of several machines writes nothing when one fails") {
  const auto dir = test::fresh_dir("robust_generate_set");
  write(dir / "bad.yaml", "weilgen: 1\nname: int\n");
  fs::create_directory(dir / "out");
  refused(dir, "generate two_axis bad.yaml --out out", 3, {"bad.yaml:2:7"});
  CHECK(fs::is_empty(dir / "out"));
}

TEST_CASE("robustness: NumberRange parses strictly and says the allowed range") {
  const auto err = [](const std::string& text, const NumberRange& r) {
    try {
      parse_number_in(text, r, "--x");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const NumberRange whole = NumberRange::whole_numbers(0, 100);
  CHECK(parse_number_in("42", whole, "--x") == 42);
  CHECK(parse_number_in("1e2", whole, "--x") == 100);
  CHECK(err("-1", whole) == "--x: '-1' is out of range (allowed: a whole number from 0 to 100)");
  CHECK(err("2.5", whole) ==
        "--x: '2.5' is not a whole number (allowed: a whole number from 0 to 100)");
  CHECK(err("", whole).find("is not a number") != std::string::npos);
  CHECK(err(" 1", whole).find("is not a number") != std::string::npos);
  CHECK(err("0x10", whole).find("is not a number") != std::string::npos);
  CHECK(err("inf", whole).find("is not a number") != std::string::npos);
  CHECK(err("1e400", NumberRange{}) == "--x: '1e400' is out of range (allowed: a number)");
  CHECK(err("0", NumberRange::open(0, 1)) ==
        "--x: '0' is out of range (allowed: a number in (0, 1))");
  CHECK(err("0", NumberRange::positive()) == "--x: '0' is out of range (allowed: a number > 0)");
  CHECK(NumberRange::left_open(0, 1).contains(1));
  CHECK(!NumberRange::left_open(0, 1).contains(0));
  CHECK(!NumberRange{}.contains(std::nan("")));
}

TEST_CASE("robustness: atomic writes go through a private temporary, fsync'ed, then rename") {
  const auto dir = test::fresh_dir("robust_atomic");
  const std::string target = (dir / "out.txt").string();
  // A stale temporary of this process id and a symbolic link in its place are not followed.
  const std::string tmp = temporary_path_for(target);
  const std::string victim = (dir / "victim.txt").string();
  write(victim, "untouched");
  fs::create_symlink(victim, tmp);
  write_file_atomically(target, "new");
  CHECK(test::read_text(target) == "new");
  CHECK(test::read_text(victim) == "untouched");
  CHECK(!fs::exists(fs::symlink_status(tmp)));
  write_file_atomically(target, "private", 0600);
  struct stat st {};
  REQUIRE(::stat(target.c_str(), &st) == 0);
  CHECK(test::read_text(target) == "private");
  // An unwritable place: a clear error, the target untouched.
  CHECK_THROWS_WITH_AS(write_file_atomically((dir / "out.txt" / "x").string(), "x"),
                       doctest::Contains("cannot write"), std::runtime_error);
  CHECK(unreadable_reason(dir.string()).find("is a directory") == 0);
  CHECK(unreadable_reason((dir / "nope").string()) == "no such file");
  CHECK(unreadable_reason(target) == "");
}
