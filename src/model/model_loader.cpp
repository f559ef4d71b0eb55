#include "weilgen/model/model_loader.hpp"

#include <dlfcn.h>
#include <pwd.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "model_cache.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/machine/model_key.hpp"

namespace weilgen {

namespace fs = std::filesystem;

namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

bool executable_on_path(const std::string& program) {
  if (program.find('/') != std::string::npos) return ::access(program.c_str(), X_OK) == 0;
  std::istringstream path(env("PATH"));
  for (std::string dir; std::getline(path, dir, ':');) {
    if (dir.empty()) continue;
    if (::access((dir + "/" + program).c_str(), X_OK) == 0) return true;
  }
  return false;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// A cached object built for an older ABI version gives nullptr when `stale_ok` (it is then
// compiled again); any other mismatch is an error.
std::shared_ptr<Model> open_shared_object(const Description& desc, const std::string& path,
                                          const std::string& key, const std::string& how,
                                          bool stale_ok = false) {
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw std::runtime_error("cannot load " + path + ": " + ::dlerror());
  std::shared_ptr<void> keep(handle, [](void* h) { ::dlclose(h); });
  using Entry = const WeilgenModelAbi* (*)();
  auto entry = reinterpret_cast<Entry>(::dlsym(handle, "weilgen_model_abi"));
  if (!entry) throw std::runtime_error(path + " has no weilgen_model_abi entry point");
  const WeilgenModelAbi* abi = entry();
  if (stale_ok && abi->abi_version != kWeilgenModelAbiVersion) return nullptr;
  if (abi->abi_version != kWeilgenModelAbiVersion || key != abi->key)
    throw std::runtime_error(path + " is not the model for this machine file (key mismatch)");
  return std::make_shared<Model>(desc, abi, ModelEngine::Compiled, how + " (" + path + ")",
                                 std::move(keep));
}

std::string compile_model(const Description& desc, int order, const std::string& key,
                          const std::string& compiler, const std::string& cache,
                          const LoadOptions& options) {
  if (!options.generate) throw std::runtime_error("no generator available to compile " + desc.name);
  const auto t0 = std::chrono::steady_clock::now();
  const GeneratedHeader header = options.generate(desc, order);
  std::error_code ec;
  model_cache::create_directory(cache);
  const fs::path work = fs::path(cache) / ("build-" + key + "-" + std::to_string(::getpid()));
  fs::create_directories(work, ec);
  if (ec) throw std::runtime_error("cannot create " + work.string() + ": " + ec.message());
  struct Cleanup {
    fs::path p;
    ~Cleanup() {
      std::error_code e;
      fs::remove_all(p, e);
    }
  } cleanup{work};
  const auto write = [](const fs::path& p, const std::string& text) {
    std::ofstream out(p, std::ios::binary);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + p.string());
  };
  write(work / "model.hpp", header.text);
  write(work / "weilgen_model_abi.hpp", kModelAbiSource);
  write(work / "shim.cpp",
        "// Run-time compilation unit of weilgen: exposes the generated model through the C "
        "ABI.\n#include \"model.hpp\"\n#include \"weilgen_model_abi.hpp\"\n\n"
        "WEILGEN_DEFINE_MODEL_ABI(weilgen_models::" +
            header.name_space +
            ", weilgen_model_abi_instance)\n\n"
            "extern \"C\" __attribute__((visibility(\"default\"))) const WeilgenModelAbi* "
            "weilgen_model_abi() {\n  return &weilgen_model_abi_instance;\n}\n");
  const fs::path so_tmp = work / "model.so";
  const fs::path log = work / "compile.log";
  const std::string cmd =
      compiler + " -std=c++17 -O2 -fPIC -shared -o " + shell_quote(so_tmp.string()) + " " +
      shell_quote((work / "shim.cpp").string()) + " > " + shell_quote(log.string()) + " 2>&1";
  if (options.log)
    options.log("compiling model " + desc.name + " (order " + std::to_string(order) + ") with " +
                compiler + " ...");
  const int status = std::system(cmd.c_str());
  if (status != 0) {
    std::string text;
    read_file(log.string(), text);
    if (text.size() > 2000) text = text.substr(0, 2000) + "\n...";
    throw std::runtime_error("compiling the model of " + desc.name + " failed (" + cmd + "):\n" +
                             text);
  }
  const fs::path target = fs::path(cache) / (desc.name + "-" + key + ".so");
  std::string object;
  if (!read_file(so_tmp.string(), object))
    throw std::runtime_error("cannot read the compiled model " + so_tmp.string());
  // With its checksum, fsync'ed, renamed into place: concurrent runs never see a partial object.
  model_cache::store_entry(object, target.string());
  if (options.log) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::ostringstream msg;
    msg.precision(2);
    msg << std::fixed << "compiled " << desc.name << " in " << s << " s -> " << target.string();
    options.log(msg.str());
  }
  return target.string();
}

}  // namespace

std::string default_cache_dir() {
  if (const std::string d = env("WEILGEN_CACHE_DIR"); !d.empty()) return d;
  if (const std::string d = env("XDG_CACHE_HOME"); !d.empty()) return d + "/weilgen";
  if (const std::string h = env("HOME"); !h.empty()) return h + "/.cache/weilgen";
  // No environment: the account's home, else a per-user directory in /tmp (checked like any).
  if (const passwd* pw = ::getpwuid(::geteuid()); pw && pw->pw_dir && *pw->pw_dir)
    return std::string(pw->pw_dir) + "/.cache/weilgen";
  return "/tmp/weilgen-cache-" + std::to_string(::geteuid());
}

std::string find_compiler(const std::string& requested) {
  if (requested == "none") return "";
  if (!requested.empty()) {
    const std::string program = requested.substr(0, requested.find(' '));
    return executable_on_path(program) ? requested : "";
  }
  if (const std::string cxx = env("CXX"); !cxx.empty()) return find_compiler(cxx);
  for (const char* c : {"c++", "g++", "clang++"})
    if (executable_on_path(c)) return c;
  return "";
}

std::shared_ptr<Model> load_model(const Description& desc, const LoadOptions& options) {
  const int order = options.order > 0 ? options.order : desc.algebra.order;
  const std::string key = model_key(desc.source_hash, order);
  const auto numeric = [&](const std::string& why) {
    return std::make_shared<Model>(desc, order, "numeric chain (" + why + ")");
  };
  if (options.engine == EngineChoice::Numeric) return numeric("requested");

  for (const WeilgenModelAbi* abi : options.builtins) {
    if (abi->abi_version == kWeilgenModelAbiVersion && key == abi->key)
      return std::make_shared<Model>(desc, abi, ModelEngine::BuiltIn, "built-in", nullptr);
  }

  const std::string cache = options.cache_dir.empty() ? default_cache_dir() : options.cache_dir;
  const fs::path cached = fs::path(cache) / (desc.name + "-" + key + ".so");
  // Nothing is loaded from a directory others could have written.
  model_cache::check_directory(cache);
  std::string damage;
  switch (model_cache::check_entry(cached.string(), damage)) {
    case model_cache::EntryState::Intact:
      // An entry built for an older ABI version gives nullptr: compiled again and replaced.
      if (auto model = open_shared_object(desc, cached, key, "cached", true)) return model;
      break;
    case model_cache::EntryState::Damaged: {
      std::error_code ec;
      fs::remove(cached, ec);
      if (options.log)
        options.log("note: the cached model " + cached.string() + " " + damage +
                    "; discarded, it is compiled again");
      break;
    }
    case model_cache::EntryState::Missing:
      break;
  }

  const std::string compiler = find_compiler(options.compiler);
  if (compiler.empty()) {
    const std::string why =
        options.compiler == "none"
            ? std::string("compilation disabled")
            : "no C++ compiler found (tried " +
                  (options.compiler.empty() ? std::string("$CXX, c++, g++, clang++")
                                            : options.compiler) +
                  ")";
    if (options.engine == EngineChoice::Compiled)
      throw std::runtime_error("cannot compile the model of " + desc.name + ": " + why);
    if (options.log)
      options.log("warning: " + why + "; evaluating " + desc.name +
                  " through the exact numeric Eigen chain instead of a compiled model (same "
                  "results up to the truncation order, about 600x slower). Install g++ or set "
                  "CXX to compile it.");
    return numeric(why);
  }
  return open_shared_object(desc, compile_model(desc, order, key, compiler, cache, options), key,
                            "compiled");
}

}  // namespace weilgen
