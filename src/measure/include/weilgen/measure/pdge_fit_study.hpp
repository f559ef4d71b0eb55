// The fits of every position-dependent error profile of a measurement file: the profiles (a 6D
// line file's six errors in ISO names, or a point/line file's deviation columns against its
// axis), the bases asked for, each fitted with its order (and Fourier period) chosen by
// cross-validation. What `weilgen fit-pdge` computes; docs/fit-pdge.md.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/measure/pdge_fit.hpp"

namespace weilgen {

// The flags of `weilgen fit-pdge`, as written.
struct PdgeFitStudyOptions {
  std::vector<std::string> bases;  // "all" (default) or KIND[:ORDER[:PERIOD]], comma lists
  std::string order = "auto";      // order of bases given without one
  std::string period = "travel";   // Fourier period of bases given without one
  std::string cv = "blocks";       // blocks | cycles
  std::string rule = "1se";        // 1se | min
  int min_order = 0, max_order = 10, folds = 10;
  std::vector<std::string> columns;  // profiles to fit; empty: all
  std::string axis;                  // position column of a non-6D file
  std::string travel;                // "a:b" mm; empty: the data's extent
  bool keep_line = false;            // 6D: keep the straightness reference line
  std::string angular = "mean";      // 6D: mean | none

  // Throws std::invalid_argument naming the flag.
  void validate() const;
};

// Where a 6D profile came from (the line6d conversion record).
struct PdgeProfileSource {
  std::string error, kind, unit, source, removed;  // removed: line | mean | none
  int sign = 1;
  double intercept = 0, slope_per_mm = 0;
};

// One profile: y(x) with its unit.
struct PdgeProfile {
  std::string name;    // E_YX or dx_um
  std::string column;  // CSV column (E_YX: the laser channel or the ISO column)
  std::string unit;    // um or urad
  std::vector<double> x, y;
  std::vector<int> cycle;                   // empty without a cycle column
  std::optional<PdgeProfileSource> source;  // 6D files
};

struct PdgeFitStudyResult {
  std::string file, format = "points", axis;  // format: points | line6d
  std::size_t rows = 0;
  std::string line6d_spelling;                        // 6D: laser | iso
  std::vector<PdgeProfileSource> line6d_conversions;  // 6D: every profile of the file
  std::vector<BasisSpec> specs;
  PdgeFitOptions fit_options;
  double travel_a = 0, travel_b = 0;  // mm
  std::vector<PdgeProfile> profiles;
  // results[i][k]: profile i, spec k; failures[i][k] non-empty when the data could not
  // support the basis (results[i][k].spec set, the rest empty).
  std::vector<std::vector<PdgeFitResult>> results;
  std::vector<std::vector<std::string>> failures;
  std::size_t failed = 0;
  std::vector<std::string> warnings;  // the reader's (implausible values), for stderr
};

class PdgeFitStudy {
 public:
  explicit PdgeFitStudy(PdgeFitStudyOptions options);  // validates the options
  const PdgeFitStudyOptions& options() const { return options_; }
  // Reads `path`; InputError for bad files, std::invalid_argument for flags the data cannot
  // honour (an unknown --column, no varying axis).
  PdgeFitStudyResult run(const std::string& path) const;

 private:
  PdgeFitStudyOptions options_;
};

}  // namespace weilgen
