// The weilgen CLI: one executable, one function per verb.
#pragma once

#include <string>
#include <vector>

namespace weilgen::cli {

using Args = std::vector<std::string>;  // arguments after the verb

int verb_generate(const Args& args);
int verb_show(const Args& args);
int verb_list(const Args& args);

// Prints "weilgen <verb>: <message>" to stderr and returns 2 (usage error).
int usage_error(const std::string& verb, const std::string& message);

}  // namespace weilgen::cli
