// Output paths checked before any work: an output is never an input or another output, never a
// directory, and its directory is writable (std::invalid_argument naming the flag: exit 2). One
// home for the CLI and the Python module.
#pragma once

#include <string>
#include <vector>

namespace weilgen {

// A file a command reads or writes, and the flag that names it ("" for a positional argument,
// e.g. the machine or data file).
struct PathArg {
  std::string flag;  // "--json", "--data", "machine file"
  std::string path;
};

// Refuses (std::invalid_argument, exit 2) an output that is one of the inputs or another output
// (compared as canonical paths, so ./a.csv, a.csv and a symbolic link to it are the same file),
// and an output that is an existing directory. Empty paths are skipped.
void check_output_paths(const std::vector<PathArg>& inputs, const std::vector<PathArg>& outputs);

// An output directory (gap --plot DIR): refused when it is an input or an existing file, or
// cannot be created.
void check_output_dir(const std::vector<PathArg>& inputs, const PathArg& dir);

}  // namespace weilgen
