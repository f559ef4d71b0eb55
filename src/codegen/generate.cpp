#include "weilgen/codegen/generate.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/codegen/emit_c_api.hpp"
#include "weilgen/codegen/emit_cpp.hpp"
#include "weilgen/codegen/emit_report.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace weilgen::gen {

std::string source_label(const std::string& machine_path) {
  // From the path alone, never from where this binary was built or installed: the same file
  // gives the same banner from every weilgen.
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(machine_path, ec);
  const fs::path file = fs::path(machine_path).filename();
  if (!ec && p.parent_path().filename() == "machines") return "machines/" + file.string();
  return file.string();
}

namespace {
SymbolicModel named_model(const Description& desc, int order_override) {
  SymbolicModel named = build_model(desc, order_override);
  if (order_override > 0 && order_override != desc.algebra.order)
    named.desc.name += "_o" + std::to_string(order_override);
  return named;
}
}  // namespace

std::string generate_header(const Description& desc, int order_override, std::string* name_space) {
  const SymbolicModel named = named_model(desc, order_override);
  if (name_space) *name_space = named.desc.name;
  return emit_cpp_header(named, source_label(desc.source_file));
}

std::vector<GeneratedFile> generate_files(const Description& desc, int order_override,
                                          const std::string& out_dir, bool c_api) {
  const SymbolicModel named = named_model(desc, order_override);
  const std::string label = source_label(desc.source_file);
  const std::string base = (std::filesystem::path(out_dir) / named.desc.name).string();
  std::vector<GeneratedFile> files = {{base + ".hpp", emit_cpp_header(named, label)},
                                      {base + ".md", emit_report_markdown(named, label)}};
  if (c_api) {
    files.push_back({base + "_c.h", emit_c_api_header(named, label)});
    files.push_back({base + "_c.cpp", emit_c_api_source(named, label)});
  }
  return files;
}

namespace {
std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}
}  // namespace

std::vector<std::string> stale_files(const std::vector<GeneratedFile>& files) {
  std::vector<std::string> stale;
  for (const auto& f : files) {
    std::string old;
    if (!read_file(f.path, old)) {
      stale.push_back(f.path + ": missing");
      continue;
    }
    if (old == f.contents) continue;
    const auto a = lines_of(old), b = lines_of(f.contents);
    std::size_t differ = 0, first = 0;
    for (std::size_t i = 0; i < std::max(a.size(), b.size()); ++i) {
      const bool same = i < a.size() && i < b.size() && a[i] == b[i];
      if (!same && differ++ == 0) first = i + 1;
    }
    stale.push_back(f.path + ": stale, " + std::to_string(differ) + " of " +
                    std::to_string(b.size()) + " lines differ, first at line " +
                    std::to_string(first));
  }
  return stale;
}

}  // namespace weilgen::gen
