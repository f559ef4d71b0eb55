// What each fuzz harness does with one input, shared by the libFuzzer harnesses (fuzz_*.cpp)
// and the regression test that replays every input the fuzzers once crashed on
// (tests/test_fuzz_regressions.cpp over fuzz/regressions/<target>/).
//
// The oracle: a reader may reject any input, but only the way the CLI documents — an InputError
// (file:line:column, exit 3) from the file readers, std::invalid_argument from the expression
// parser. Any other exception escaping (it would be exit 1 without a location), a crash, a hang
// or a sanitizer report is a bug. The expression target also checks that an expression printed
// and read back has the same value.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>

#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/error.hpp"
#include "weilgen/base/expr.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen::fuzz {

// A failed oracle: print it and abort, so that libFuzzer saves the input.
[[noreturn]] inline void bug(const char* target, const std::string& what) {
  std::fprintf(stderr, "fuzz target %s: %s\n", target, what.c_str());
  std::abort();
}

inline void machine_yaml(const std::string& text) {
  try {
    const Description d = load_machine_text(text, "fuzz.yaml");
    (void)d;
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    bug("machine_yaml", std::string("exception other than InputError: ") + e.what());
  }
}

inline void measurement_csv(const std::string& text) {
  ReadOptions free;  // no machine: any single capital is a coordinate
  ReadOptions machine;
  machine.coordinates = {"X", "Y", "Z", "C"};
  machine.machine = "fuzz_machine";
  machine.travel = {{"X", "mm", 0, 1000}, {"C", "deg", -180, 180}};
  machine.allow_unknown = true;
  for (const ReadOptions* o : {&free, &machine}) {
    try {
      const MeasurementTable t = parse_measurements(text, "fuzz.csv", *o);
      for (std::size_t c = 0; c < t.columns.size(); ++c)
        if (t.values.at(t.columns[c]).size() != t.rows()) bug("measurement_csv", "ragged table");
    } catch (const InputError&) {
    } catch (const std::exception& e) {
      bug("measurement_csv", std::string("exception other than InputError: ") + e.what());
    }
  }
}

// The tolerance file of `text` against the shipped grinder (`machine`, loaded once).
inline void tolerance_file(const std::string& text, const Description& machine) {
  try {
    const ToleranceOverrides t = read_tolerance_text(text, "fuzz.yaml", machine);
    if (t.size() != machine.errors.size()) bug("tolerance_file", "wrong number of entries");
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    bug("tolerance_file", std::string("exception other than InputError: ") + e.what());
  }
}

inline bool same_value(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  if (!std::isfinite(a) || !std::isfinite(b)) return a == b;
  return a == b || std::fabs(a - b) <= 1e-12 * std::fmax(std::fabs(a), std::fabs(b));
}

// The first byte chooses: an expression (parsed, evaluated with every parameter = 1.5, printed,
// read back and evaluated again) or a quantity with a unit ("0.05/6 mm").
inline void expression(const std::string& input) {
  if (input.empty()) return;
  const std::string text = input.substr(1);
  if (input[0] & 1) {
    try {
      parse_quantity_unit(text, "mm", "fuzz");
    } catch (const std::invalid_argument&) {
    } catch (const std::exception& e) {
      bug("expression",
          std::string("quantity: exception other than invalid_argument: ") + e.what());
    }
    return;
  }
  Expr e;
  try {
    e = parse_expr(text);
  } catch (const std::invalid_argument&) {
    return;
  } catch (const std::exception& ex) {
    bug("expression", std::string("exception other than invalid_argument: ") + ex.what());
  }
  std::map<std::string, double> values;
  for (const std::string& p : e.params()) values[p] = 1.5;
  const double v = e.eval(values);
  const std::string printed = e.str();
  Expr back;
  try {
    back = parse_expr(printed);
  } catch (const std::exception& ex) {
    bug("expression",
        "'" + text + "' prints as '" + printed + "', which does not parse: " + ex.what());
  }
  const double w = back.eval(values);
  // Printing may regroup a sum or a product; the value must survive (to rounding).
  if (!same_value(v, w))
    bug("expression", "'" + text + "' = " + std::to_string(v) + " prints as '" + printed +
                          "' = " + std::to_string(w));
}

}  // namespace weilgen::fuzz
