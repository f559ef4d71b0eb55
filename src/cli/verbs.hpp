// The weilgen CLI: one executable, one function per verb.
#pragma once

#include <boost/program_options.hpp>
#include <optional>
#include <string>
#include <vector>

namespace weilgen::cli {

using Args = std::vector<std::string>;  // arguments after the verb

int verb_generate(const Args& args);
int verb_show(const Args& args);
int verb_list(const Args& args);
int verb_sensitivity(const Args& args);
int verb_reliability(const Args& args);
int verb_allocate(const Args& args);
int verb_iso230_2(const Args& args);
int verb_ballbar(const Args& args);
int verb_import(const Args& args);
int verb_fit_pdge(const Args& args);
int verb_identify(const Args& args);
int verb_gap(const Args& args);
int verb_plan(const Args& args);
int verb_linuxcnc(const Args& args);

// Prints "weilgen <verb>: <message>" to stderr and returns 2 (usage error).
int usage_error(const std::string& verb, const std::string& message);

// Parses a verb's arguments: `visible` options plus positional arguments stored under
// `positional` (at most `max_positional`, -1 for any number, each a `Positional`). Returns an
// exit code when the verb should stop (0 after printing --help, 2 on bad arguments).
template <typename Positional>
std::optional<int> parse_args(const std::string& verb, const Args& args,
                              const boost::program_options::options_description& visible,
                              const char* positional, int max_positional,
                              boost::program_options::variables_map& vm);

}  // namespace weilgen::cli
