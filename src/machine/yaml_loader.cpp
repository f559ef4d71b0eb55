#include "weilgen/machine/yaml_loader.hpp"

#include <dlfcn.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>

#include "loader.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/machine/derived.hpp"
#include "weilgen/machine/iso_names.hpp"
#include "weilgen/machine/linuxcnc.hpp"
#include "weilgen/machine/model_key.hpp"
#include "weilgen/machine/pdge_basis.hpp"

#ifndef WEILGEN_MACHINES_DIR
#define WEILGEN_MACHINES_DIR "machines"
#endif

namespace weilgen::machine_detail {

Description Loader::load(const YAML::Node& root) {
  if (!root.IsMap()) {
    throw InputError({file_, 1, 1},
                     "a machine file is a YAML mapping (weilgen: 1, name, "
                     "bodies, tool, workpiece, ...)");
  }
  const MapView top = map({root, root, ""}, kTopKeys);
  read_version(required(top, "weilgen"));
  d_.name = identifier(required(top, "name").value, "machine name");
  if (const Entry* e = top.find("title")) d_.title = text(e->value);
  if (const Entry* e = top.find("notes")) d_.notes = text(e->value);
  d_.groups = builtin_groups();
  if (const Entry* e = top.find("parameters")) read_parameters(e->value);
  if (const Entry* e = top.find("groups")) read_groups(e->value);
  if (const Entry* e = top.find("error_defaults")) read_error_defaults(e->value);
  read_bodies(required(top, "bodies"));
  if (const Entry* e = top.find("points")) read_points(e->value);
  if (const Entry* e = top.find("directions")) read_directions(e->value);
  if (const Entry* e = top.find("derived")) read_derived(e->value);
  if (const Entry* e = top.find("output")) {
    for (const char* key : {"tool", "workpiece"}) {
      if (const Entry* t = top.find(key)) {
        fail_at(t->key_node, "",
                std::string("'") + key +
                    "' does not apply: this machine's output is the 'output' transform");
      }
    }
    d_.output = read_output(e->value);
  } else {
    d_.tool = read_point_spec(required(top, "tool").value);
    d_.workpiece = read_point_spec(required(top, "workpiece").value);
  }
  if (const Entry* e = top.find("algebra")) read_algebra(e->value);
  if (const Entry* e = top.find("pdge_basis")) read_pdge_basis(e->value);
  if (const Entry* e = top.find("linuxcnc")) read_linuxcnc(e->value);
  d_.source_file = file_;
  check_derived(d_);
  if (top.find("linuxcnc")) linuxcnc_mapping(d_);  // letters and joints used twice, gaps
  return std::move(d_);
}

std::string Loader::basis_text(const Field& f) const {
  const std::string s = text(f);
  try {
    parse_basis(s);
  } catch (const std::invalid_argument& e) {
    fail(f, e.what());
  }
  return s;
}

Distribution Loader::distribution_keys(const YAML::Node& node, const std::string& path) const {
  return read_distribution(map({node, node, path}, {})).value_or(Distribution{});
}

}  // namespace weilgen::machine_detail

namespace weilgen {

using machine_detail::is_identifier;
using machine_detail::Loader;

YAML::Node parse_yaml(const std::string& text, const std::string& filename) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& ex) {
    throw InputError({filename, ex.mark.line + 1, ex.mark.column + 1},
                     "YAML syntax error: " + ex.msg);
  }
}

Description load_machine_text(const std::string& yaml, const std::string& filename) {
  const YAML::Node root = parse_yaml(yaml, filename);
  Description desc = Loader(filename).load(root);
  desc.source_hash = fnv1a64(yaml);
  return desc;
}

Description load_machine_file(const std::string& path) {
  std::string text;
  if (const std::string why = unreadable_reason(path); !why.empty() || !read_file(path, text))
    throw InputError({path, 0, 0},
                     "cannot read the machine file: " + (why.empty() ? "read error" : why));
  return load_machine_text(text, path);
}

Distribution read_distribution_keys(const YAML::Node& mapping, const std::string& file,
                                    const std::string& path) {
  return Loader(file).distribution_keys(mapping, path);
}

namespace {
std::string& machines_dir_choice() {
  static std::string dir;
  return dir;
}
}  // namespace

void use_shipped_machines_dir(const std::string& dir) { machines_dir_choice() = dir; }

std::string shipped_machines_dir() {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (const char* env = std::getenv("WEILGEN_MACHINES_DIR"); env && *env) return env;
  if (!machines_dir_choice().empty()) return machines_dir_choice();
  // An installed weilgen reads its installed copy even while the source tree it was built from
  // still exists: <prefix>/share/weilgen/machines a few levels above the binary holding this code
  // (<prefix>/bin/weilgen, or the Python module in <prefix>/lib/python3.X/dist-packages/weilgen).
  static const int anchor = 0;  // an address inside this binary
  Dl_info info{};
  const bool module = dladdr(&anchor, &info) != 0 && info.dli_fname &&
                      fs::path(info.dli_fname).extension() == ".so";
  fs::path binary =
      module ? fs::absolute(info.dli_fname, ec) : fs::read_symlink("/proc/self/exe", ec);
  if (!ec && !binary.empty()) {
    fs::path dir = binary.parent_path();
    for (int up = 0; up < 5 && dir.has_parent_path() && dir != dir.root_path(); ++up) {
      dir = dir.parent_path();
      const fs::path installed = dir / "share" / "weilgen" / "machines";
      if (fs::is_directory(installed, ec)) return installed.string();
    }
  }
  return WEILGEN_MACHINES_DIR;  // the source tree's
}

std::vector<std::string> shipped_machine_files() {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(shipped_machines_dir(), ec))
    if (e.path().extension() == ".yaml") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string resolve_machine(const std::string& name_or_path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_regular_file(name_or_path, ec)) return name_or_path;
  const std::string dir = shipped_machines_dir();
  const fs::path shipped = fs::path(dir) / (name_or_path + ".yaml");
  if (is_identifier(name_or_path) && fs::is_regular_file(shipped, ec)) return shipped.string();
  // Anything else that exists (a directory, a device): load_machine_file says what it is.
  if (fs::exists(name_or_path, ec)) return name_or_path;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  throw InputError({name_or_path, 0, 0},
                   "no such machine file, and no shipped machine of that name (shipped: " +
                       (names.empty() ? std::string("none") : join(names)) + ")");
}

}  // namespace weilgen
