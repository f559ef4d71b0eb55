// The CLI's checks of what a command line asks for, shared by every verb (and by verbs other
// developers add): numeric flags read strictly and range-checked as they are parsed, output
// paths that must not be inputs, the algebra order. Every refusal is a std::invalid_argument or
// a boost::program_options error naming the flag: exit 2, before anything is computed or written.
#pragma once

#include <boost/program_options.hpp>
#include <charconv>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "weilgen/base/format.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/base/range.hpp"
#include "weilgen/machine/description.hpp"

namespace weilgen::cli {

// What a numeric flag admits, for the flag table of `weilgen <verb> --flags-json` (the Python
// module checks its keywords against the same ranges, docs/python.md).
class RangedSemantic {
 public:
  virtual ~RangedSemantic() = default;
  virtual const NumberRange& range() const = 0;
};

// A numeric flag value: the whole token is the number (no "12abc"; "-1" is no unsigned), NaN and
// infinities are refused, and the number must lie in `range`. A bad value stops the parse with
// "--bootstrap: '-1' is out of range (allowed: a whole number from 0 to 100000)".
template <typename T>
class RangedValue : public boost::program_options::typed_value<T>, public RangedSemantic {
 public:
  RangedValue(T* store, NumberRange range)
      : boost::program_options::typed_value<T>(store), range_(range) {
    if (std::is_integral_v<T>) range_.whole = true;
  }

  // The default shown by --help as the number is written ("0.95", not lexical_cast's
  // "0.94999999999999996"); default_value(v, "text") still sets the text explicitly.
  using boost::program_options::typed_value<T>::default_value;
  RangedValue* default_value(const T& v) {
    boost::program_options::typed_value<T>::default_value(v, format_number(static_cast<double>(v)));
    return this;
  }

  const NumberRange& range() const override { return range_; }

  void xparse(boost::any& value_store, const std::vector<std::string>& tokens) const override {
    namespace po = boost::program_options;
    const std::string& text = po::validators::get_single_string(tokens);
    try {
      value_store = boost::any(read(text));
    } catch (const std::invalid_argument& e) {
      // Boost puts the flag's name in place of %canonical_option%.
      throw po::error_with_option_name(e.what());
    }
  }

 private:
  T read(const std::string& text) const {
    const char* what = "%canonical_option%";
    if constexpr (std::is_integral_v<T>) {
      T v{};
      const char* first = text.data() + (text.size() > 1 && text[0] == '+' ? 1 : 0);
      const auto [end, ec] = std::from_chars(first, text.data() + text.size(), v);
      if (ec == std::errc() && end == text.data() + text.size() &&
          range_.contains(static_cast<double>(v)))
        return v;
      // Out of range, or not a plain integer of T ("-1" unsigned, "1e3", "2.5", "abc"): read as
      // a number (which says what is wrong), then keep it only when T holds it.
      const double d = parse_number_in(text, range_, what);
      if (d >= static_cast<double>(std::numeric_limits<T>::min()) &&
          d < static_cast<double>(std::numeric_limits<T>::max()))
        return static_cast<T>(d);
      throw std::invalid_argument(std::string(what) + ": '" + text +
                                  "' is out of range (allowed: " + range_.text() + ")");
    } else {
      return static_cast<T>(parse_number_in(text, range_, what));
    }
  }

  NumberRange range_;
};

template <typename T>
RangedValue<T>* ranged(T* store, NumberRange range) {
  return new RangedValue<T>(store, range);
}

// A verb's flags as data (`weilgen <verb> --flags-json`): for every visible option its name, kind
// (switch, repeatable, number, whole, text), default as --help shows it, allowed range and help
// text, and the verb's description. The Python module's keywords, signatures, stub and range
// checks are built from it, and its parity test compares them with it (docs/python.md).
nlohmann::json flags_json(const std::string& verb,
                          const boost::program_options::options_description& visible,
                          const char* positional, int max_positional);

// --threads: 0 (every core) to 1024.
NumberRange thread_range();

// The algebra order asked by --order (0 = the file's): refuses a model too large to generate
// (exit 2, with the estimate of its terms) and prints a warning with the estimate for a large one
// to stderr (unless quiet).
void check_order(const Description& desc, int order, bool quiet);

}  // namespace weilgen::cli
