// Finds a compiled model for a machine description, or makes one:
//   1. a built-in model with the same content key (model_key.hpp) — the shipped machines;
//   2. a shared object in the cache with that key, compiled earlier;
//   3. otherwise: generate the header (the caller's `generate`, which runs the GiNaC generator),
//      compile it with the system C++ compiler into the cache, load it;
//   4. no compiler found: the exact numeric Eigen chain, with a warning (slower, same interface).
// The runtime library itself does not link GiNaC: generation is injected by the caller.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "weilgen/model/model.hpp"

namespace weilgen {

struct GeneratedHeader {
  std::string text;        // the header's contents
  std::string name_space;  // e.g. "gantry_grinder" or "gantry_grinder_o2" (under weilgen_models)
};

enum class EngineChoice { Auto, Compiled, Numeric };

struct LoadOptions {
  int order = 0;  // algebra order; 0 = the machine file's
  EngineChoice engine = EngineChoice::Auto;
  // Compiled models are cached here; default $WEILGEN_CACHE_DIR, else $XDG_CACHE_HOME/weilgen,
  // else $HOME/.cache/weilgen.
  std::string cache_dir;
  // Compiler command; default $CXX, else the first of c++, g++, clang++ on PATH. "none"
  // disables compilation.
  std::string compiler;
  std::vector<const WeilgenModelAbi*> builtins;  // models compiled into the executable
  std::function<GeneratedHeader(const Description&, int order)> generate;
  std::function<void(const std::string&)> log;  // progress and warnings (e.g. to stderr)
};

std::shared_ptr<Model> load_model(const Description& desc, const LoadOptions& options);

// The resolved defaults (for messages and docs).
std::string default_cache_dir();
std::string find_compiler(const std::string& requested);  // "" when none is found

// The text of model_abi.hpp (embedded at build time; handed to the run-time compiler).
extern const char* const kModelAbiSource;

}  // namespace weilgen
