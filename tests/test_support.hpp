// Shared helpers for the test suite.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/machine/description.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"

namespace weilgen::test {

// A fresh, empty directory under the test build's tmp/.
inline std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(WEILGEN_TEST_TMP) / name;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

// A shell command's exit status and combined stdout + stderr.
struct Run {
  int status = -1;
  std::string out;
};

// `out` without what a sanitizer adds when the suite runs instrumented (scripts/sanitize.sh):
// "==1234==..." lines and the "Suppressions used:" block between dashed lines. A real sanitizer
// report also changes the exit status (scripts/sanitize.sh sets exitcode), so nothing is hidden.
inline std::string without_sanitizer_banners(const std::string& out) {
  std::string kept;
  bool in_block = false;
  std::size_t pos = 0;
  while (pos < out.size()) {
    std::size_t nl = out.find('\n', pos);
    nl = nl == std::string::npos ? out.size() : nl + 1;
    const std::string line = out.substr(pos, nl - pos);
    pos = nl;
    if (line.rfind("-----------------------------------------------------", 0) == 0) {
      in_block = !in_block;
      continue;
    }
    const bool banner = line.size() > 2 && line[0] == '=' && line[1] == '=' &&
                        line.find("==", 2) != std::string::npos;
    if (in_block || banner) continue;
    kept += line;
  }
  return kept;
}

inline Run run(const std::string& cmd) {
  Run r;
  FILE* pipe = popen((cmd + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) r.out += buf;
  const int status = pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = without_sanitizer_banners(r.out);
  return r;
}

// The weilgen command line with `args`.
inline std::string cli(const std::string& args) { return std::string(WEILGEN_BINARY) + " " + args; }

// The message of loading `yaml` as a machine file named `filename` ("" when it loads).
inline std::string load_error(const std::string& yaml, const std::string& filename = "bad.yaml") {
  try {
    load_machine_text(yaml, filename);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

inline const std::vector<std::string>& shipped_machines() {
  static const std::vector<std::string> m = {"gantry_grinder", "vmc_3axis",   "two_axis",
                                             "five_axis_ac",   "pipe_cutter", "head_head_bc"};
  return m;
}

inline std::string machine_path(const std::string& name) {
  return std::string(WEILGEN_SOURCE_DIR) + "/machines/" + name + ".yaml";
}

// A pose drawn uniformly within the joints' ranges.
inline std::vector<double> random_pose(const Description& d, std::mt19937& rng) {
  std::vector<double> q;
  for (int b : d.axes()) {
    const Joint& j = d.bodies[b].joint;
    q.push_back(std::uniform_real_distribution<double>(j.min, j.max)(rng));
  }
  return q;
}

// Errors of scale s: translations s·u mm, rotations s·u·1e-3 rad, u uniform in [-1, 1].
inline std::vector<double> random_direction(const Description& d, std::mt19937& rng) {
  std::vector<double> u;
  for (const auto& e : d.errors) {
    const double v = std::uniform_real_distribution<double>(-1, 1)(rng);
    u.push_back(e.effect == ErrorEffect::Rotation ? v * 1e-3 : v);
  }
  return u;
}

inline std::vector<double> scaled(const std::vector<double>& u, double s) {
  std::vector<double> v(u);
  for (auto& x : v) x *= s;
  return v;
}

inline double max_abs_diff(const std::array<double, 6>& a, const std::array<double, 6>& b) {
  double m = 0;
  for (int i = 0; i < 6; ++i) m = std::max(m, std::abs(a[i] - b[i]) * (i < 3 ? 1.0 : 1000.0));
  return m;
}

// Least-squares slope of log(err) against log(s).
inline double loglog_slope(const std::vector<double>& s, const std::vector<double>& err) {
  double mx = 0, my = 0;
  const double n = static_cast<double>(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    mx += std::log(s[i]) / n;
    my += std::log(err[i]) / n;
  }
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    sxy += (std::log(s[i]) - mx) * (std::log(err[i]) - my);
    sxx += (std::log(s[i]) - mx) * (std::log(s[i]) - mx);
  }
  return sxy / sxx;
}

// A file's whole text (weilgen/base/atomic_file.hpp's read_file), "" when it cannot be read.
inline std::string read_text(const std::string& path) {
  std::string text;
  read_file(path, text);
  return text;
}

// A shipped machine's built-in model (no compiler; one per name for the whole test run).
inline std::shared_ptr<Model> builtin_model(const std::string& name) {
  static std::map<std::string, std::shared_ptr<Model>> cache;
  auto& m = cache[name];
  if (!m) {
    LoadOptions o;
    o.builtins = builtin_models();
    o.cache_dir = fresh_dir("builtin_" + name).string();
    o.compiler = "none";
    m = load_model(load_machine_file(machine_path(name)), o);
  }
  return m;
}

}  // namespace weilgen::test
