// Orchestrates generation: machine description → header + report, written atomically or checked.
#pragma once

#include <string>
#include <vector>

#include "weilgen/codegen/model_builder.hpp"

namespace weilgen::gen {

struct GeneratedFile {
  std::string path;
  std::string contents;
};

// Label naming the machine file in banners: "machines/<file>" for a file in a directory named
// machines (the shipped machines, in the source tree or installed), else the file name alone.
// Depends on the path only: output is the same from any checkout, working directory or binary.
std::string source_label(const std::string& machine_path);

// The header and report of a model, and with `c_api` its C API (<name>_c.h, <name>_c.cpp;
// emit_c_api.hpp). File and namespace names are the machine's name, with "_o<r>" appended when
// `order_override` differs from the file's order.
std::vector<GeneratedFile> generate_files(const Description& desc, int order_override,
                                          const std::string& out_dir, bool c_api = false);

// The header alone (run-time compilation, model_loader.hpp); `name_space` receives the model's
// namespace under weilgen_models.
std::string generate_header(const Description& desc, int order_override, std::string* name_space);

// Compares files with what is on disk; returns one line per stale or missing file
// ("generated/x.hpp: 12 of 340 lines differ, first at line 57").
std::vector<std::string> stale_files(const std::vector<GeneratedFile>& files);

}  // namespace weilgen::gen
