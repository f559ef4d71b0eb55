// Every input the fuzzers once crashed on (fuzz/regressions/<target>/), replayed through the same
// oracle as the libFuzzer harnesses (fuzz/targets.hpp): a reader may refuse it only the
// documented way. The seed corpora (machines/, examples/data/, machines/tolerances/,
// fuzz/corpus/expression/) run too: every shipped file passes the oracle. fuzz/README.md.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz/targets.hpp"
#include "test_support.hpp"

using namespace weilgen;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> files_in(const std::string& dir, const std::string& ext = "") {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && (ext.empty() || e.path().extension() == ext))
      out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

const std::string kSource = WEILGEN_SOURCE_DIR;

}  // namespace

TEST_CASE("fuzz regressions: every saved input passes its harness's oracle") {
  const Description grinder = load_machine_file(test::machine_path("gantry_grinder"));
  std::size_t replayed = 0;
  for (const std::string& f : files_in(kSource + "/fuzz/regressions/machine_yaml")) {
    CAPTURE(f);
    fuzz::machine_yaml(test::read_text(f));
    ++replayed;
  }
  for (const std::string& f : files_in(kSource + "/fuzz/regressions/measurement_csv")) {
    CAPTURE(f);
    fuzz::measurement_csv(test::read_text(f));
    ++replayed;
  }
  for (const std::string& f : files_in(kSource + "/fuzz/regressions/tolerance_file")) {
    CAPTURE(f);
    fuzz::tolerance_file(test::read_text(f), grinder);
    ++replayed;
  }
  for (const std::string& f : files_in(kSource + "/fuzz/regressions/expression")) {
    CAPTURE(f);
    fuzz::expression(test::read_text(f));
    ++replayed;
  }
  MESSAGE(replayed << " fuzz regression inputs replayed");
}

TEST_CASE("fuzz seeds: the shipped files and the expression seeds pass the oracle") {
  const Description grinder = load_machine_file(test::machine_path("gantry_grinder"));
  const auto machines = files_in(kSource + "/machines", ".yaml");
  CHECK(machines.size() >= 5);
  for (const std::string& f : machines) fuzz::machine_yaml(test::read_text(f));
  for (const std::string& f : files_in(kSource + "/examples/data", ".csv"))
    fuzz::measurement_csv(test::read_text(f));
  for (const std::string& f : files_in(kSource + "/machines/tolerances", ".yaml"))
    fuzz::tolerance_file(test::read_text(f), grinder);
  const auto seeds = files_in(kSource + "/fuzz/corpus/expression");
  CHECK(seeds.size() >= 10);
  for (const std::string& f : seeds) fuzz::expression(test::read_text(f));
}
