// Reads a machine description (machines/README.md) into a Description. Every problem in the input
// is reported as an InputError carrying the file and the 1-based line:column of the YAML node at
// fault; nothing is partially loaded.
#pragma once

#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"

namespace YAML {
class Node;
}

namespace weilgen {

// Reads and checks the machine file at `path`. Throws InputError.
Description load_machine_file(const std::string& path);

// Same, from YAML text; `filename` is used in messages and as Description::source_file.
Description load_machine_text(const std::string& yaml, const std::string& filename);

// A path to a file, or the name of a shipped machine (WEILGEN_MACHINES_DIR "/<name>.yaml").
// Throws InputError (loc.file = the argument) when neither exists.
std::string resolve_machine(const std::string& name_or_path);
// Where shipped machines live: $WEILGEN_MACHINES_DIR if set, else the directory a front end chose
// (the Python package's own copy), else <prefix>/share/weilgen/machines above an installed
// module (the Python module in <prefix>/lib/python3.X/dist-packages) or next to an installed
// executable, else the source tree's machines/.
std::string shipped_machines_dir();
void use_shipped_machines_dir(const std::string& dir);  // "" : no choice
// The shipped machine files (<dir>/*.yaml), sorted by name.
std::vector<std::string> shipped_machine_files();

// The distribution keys of a machine file's error or error_defaults entry, for other files that
// use the same syntax (tolerance files, weilgen/analysis/tolerance_file.hpp). `mapping` is a YAML
// mapping (null reads as empty); of its keys, `sigma`, `normal`, `uniform` and `truncnormal` are
// read (at most one may be present, values numbers or expressions such as 0.05/6, in the caller's
// unit) and the others are left to the caller. Returns Kind::None when none is present. Throws
// InputError "file:line:column: <path>.<key>: message", exactly as load_machine_file reports them.
Distribution read_distribution_keys(const YAML::Node& mapping, const std::string& file,
                                    const std::string& path);

// Parses YAML text; a syntax error throws InputError "file:line:column: YAML syntax error: ...".
YAML::Node parse_yaml(const std::string& text, const std::string& filename);

}  // namespace weilgen
