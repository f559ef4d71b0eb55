#include "flags.hpp"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <system_error>

#include "weilgen/machine/algebra_size.hpp"

namespace weilgen::cli {

namespace fs = std::filesystem;
namespace po = boost::program_options;

namespace {

// The default as --help prints it: "arg (=0.95)" -> "0.95"; none -> null.
nlohmann::json default_text(const po::option_description& o) {
  const std::string p = o.format_parameter();
  const auto open = p.find("(=");
  if (open == std::string::npos || p.empty() || p.back() != ')') return nullptr;
  return p.substr(open + 2, p.size() - open - 3);
}

nlohmann::json range_json(const NumberRange& r) {
  const auto end = [](double v) -> nlohmann::json {
    if (std::isinf(v)) return nullptr;
    return v;
  };
  return {{"lo", end(r.lo)},      {"hi", end(r.hi)},  {"lo_open", r.lo_open},
          {"hi_open", r.hi_open}, {"whole", r.whole}, {"text", r.text()}};
}

template <typename... T>
bool holds_whole(const po::value_semantic* s) {
  return (... || (dynamic_cast<const po::typed_value<T>*>(s) != nullptr));
}

}  // namespace

nlohmann::json flags_json(const std::string& verb, const po::options_description& visible,
                          const char* positional, int max_positional) {
  std::ostringstream help;
  help << visible;
  // The description: --help's text before the first option line, without the caption's
  // trailing "Options:".
  std::string about = help.str().substr(0, help.str().find("\n  -"));
  while (!about.empty() && (about.back() == '\n' || about.back() == ':')) about.pop_back();
  if (about.size() >= 7 && about.compare(about.size() - 7, 7, "Options") == 0)
    about.resize(about.size() - 7);
  while (!about.empty() && about.back() == '\n') about.pop_back();
  nlohmann::json flags = nlohmann::json::array();
  for (const auto& o : visible.options()) {
    const po::value_semantic* s = o->semantic().get();
    nlohmann::json f = {{"name", o->long_name()}, {"help", o->description()}};
    const auto* ranged = dynamic_cast<const RangedSemantic*>(s);
    if (s->max_tokens() == 0)
      f["kind"] = "switch";
    else if (s->is_composing())
      f["kind"] = "repeatable";
    else if (ranged)
      f["kind"] = ranged->range().whole ? "whole" : "number";
    else if (holds_whole<int, long, long long, unsigned, unsigned long, unsigned long long>(s))
      f["kind"] = "whole";
    else
      f["kind"] = "text";
    f["default"] = f["kind"] == "switch" ? nlohmann::json(nullptr) : default_text(*o);
    f["range"] = ranged ? range_json(ranged->range()) : nlohmann::json(nullptr);
    flags.push_back(std::move(f));
  }
  return {{"verb", verb},
          {"positional", positional},
          {"positional_count", max_positional},
          {"about", about},
          {"flags", flags}};
}

NumberRange thread_range() { return NumberRange::whole_numbers(0, 1024); }

void check_order(const Description& desc, int order, bool quiet) {
  const std::string warning = check_algebra_size(desc, order, "--order " + std::to_string(order));
  if (!warning.empty() && !quiet) std::cerr << "weilgen: " << warning << "\n";
}

}  // namespace weilgen::cli
