#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "binding.hpp"
#include "weilgen/base/range.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen::python {

namespace {

bool is_text(py::handle v) {
  return py::isinstance<py::str>(v) || py::hasattr(v, "__fspath__");  // os.PathLike (pathlib.Path)
}

bool is_number(py::handle v) {
  if (py::isinstance<py::bool_>(v)) return false;
  return py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v) ||
         (py::hasattr(v, "__float__") && !is_text(v) && !py::isinstance<py::sequence>(v));
}

std::string type_name(py::handle v) { return py::str(py::type::handle_of(v).attr("__name__")); }

py::object object(py::handle v) { return py::reinterpret_borrow<py::object>(v); }

std::string joined(const std::vector<std::string>& parts, const char* sep) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? sep : "") + parts[i];
  return out;
}

// verb -> keyword -> its flag (the flag's name with '-' as '_').
std::map<std::string, std::map<std::string, FlagSpec>>& flag_tables() {
  static std::map<std::string, std::map<std::string, FlagSpec>> tables;
  return tables;
}

std::string keyword_of(std::string flag) {
  std::replace(flag.begin(), flag.end(), '-', '_');
  return flag;
}

double end_value(const nlohmann::json& j, double infinite) {
  return j.is_null() ? infinite : j.get<double>();
}

}  // namespace

void use_flag_tables(const std::string& json_text) {
  const nlohmann::json all = nlohmann::json::parse(json_text);
  auto& tables = flag_tables();
  tables.clear();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [verb, table] : all.items()) {
    auto& specs = tables[verb];
    for (const nlohmann::json& f : table.at("flags")) {
      FlagSpec spec;
      spec.kind = f.at("kind").get<std::string>();
      if (!f.at("default").is_null()) spec.def = f.at("default").get<std::string>();
      if (const nlohmann::json& r = f.at("range"); !r.is_null()) {
        NumberRange range;
        range.lo = end_value(r.at("lo"), -inf);
        range.hi = end_value(r.at("hi"), inf);
        range.lo_open = r.at("lo_open").get<bool>();
        range.hi_open = r.at("hi_open").get<bool>();
        range.whole = r.at("whole").get<bool>();
        spec.range = range;
      }
      specs[keyword_of(f.at("name").get<std::string>())] = spec;
    }
  }
}

const FlagSpec* flag_spec(const std::string& function, const std::string& keyword) {
  // Model takes the model flags, which every model verb shares.
  const std::string verb = function == "Model" ? "sensitivity" : [&] {
    std::string v = function;
    std::replace(v.begin(), v.end(), '_', '-');
    return v;
  }();
  const auto table = flag_tables().find(verb);
  if (table == flag_tables().end()) return nullptr;
  const auto spec = table->second.find(keyword);
  return spec == table->second.end() ? nullptr : &spec->second;
}

std::map<std::string, std::vector<std::string>>& implemented_keywords() {
  static std::map<std::string, std::vector<std::string>> functions;
  return functions;
}

std::string value_text(py::handle v, const std::string& flag) {
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::hasattr(v, "__fspath__")) return py::str(v.attr("__fspath__")());
  if (is_number(v)) {
    // Integers as integers; floats as Python's repr, the shortest text that reads back exactly.
    if (py::isinstance<py::int_>(v) || py::hasattr(v, "__index__"))
      return py::str(py::int_(object(v)));
    const double d = py::float_(object(v)).cast<double>();
    if (!std::isfinite(d))
      throw std::invalid_argument(flag + ": " + py::repr(v).cast<std::string>() +
                                  " is not a finite number");
    return py::repr(py::float_(d)).cast<std::string>();
  }
  if (py::isinstance<py::tuple>(v) || py::isinstance<py::list>(v)) {  // (start, stop, count)
    std::vector<std::string> parts;
    for (py::handle x : v) parts.push_back(value_text(x, flag));
    return joined(parts, ":");
  }
  throw std::invalid_argument(flag + ": expected a str or a number, not " + type_name(v) + " (" +
                              py::repr(v).cast<std::string>() + ")");
}

Keywords::Keywords(const char* function, const py::kwargs& kwargs,
                   const std::vector<const char*>& names)
    : function_(function), kwargs_(kwargs) {
  for (auto item : kwargs_) {
    const std::string key = item.first.cast<std::string>();
    if (std::none_of(names.begin(), names.end(), [&](const char* n) { return key == n; })) {
      std::vector<std::string> known(names.begin(), names.end());
      std::sort(known.begin(), known.end());
      throw std::invalid_argument(function_ + "(): unknown keyword '" + key +
                                  "' (keywords: " + join(known) + ")");
    }
  }
  // Every value checked as the CLI parses its command line, before anything runs.
  for (const char* name : names) {
    const py::handle v = value(name);
    const FlagSpec* spec = flag_spec(function_, name);
    if (v.is_none() || !spec) continue;
    if (spec->kind == "switch") {
      flag(name);
    } else if (spec->range) {
      parse_number_in(value_text(v, flag_name(name)), *spec->range, flag_name(name));
    } else if (spec->kind == "whole") {
      integer(name);
    }
  }
}

std::string Keywords::flag_name(const char* name) const {
  std::string f = std::string("--") + name;
  std::replace(f.begin(), f.end(), '_', '-');
  return f;
}

py::handle Keywords::value(const char* name) const {
  if (!kwargs_.contains(name)) return py::none();
  return kwargs_[name];
}

bool Keywords::given(const char* name) const {
  const py::handle v = value(name);
  if (v.is_none()) return false;
  const FlagSpec* spec = flag_spec(function_, name);
  if (!spec) return true;
  if (spec->kind == "switch") return flag(name);
  if (!spec->def) return true;
  if (spec->kind == "number" || spec->kind == "whole") {
    if (!is_number(v)) return true;
    return py::float_(object(v)).cast<double>() != std::stod(*spec->def);
  }
  return !(is_text(v) || is_number(v)) || value_text(v, flag_name(name)) != *spec->def;
}

std::optional<std::string> Keywords::text(const char* name) const {
  const py::handle v = value(name);
  if (v.is_none()) return std::nullopt;
  if (!is_text(v) && !is_number(v))
    throw std::invalid_argument(flag_name(name) + ": expected a str, not " + type_name(v));
  return value_text(v, flag_name(name));
}

std::vector<std::string> Keywords::items(const char* name, bool one_flag) const {
  const py::handle v = value(name);
  const std::string flag = flag_name(name);
  const auto dict_items = [&](py::handle d) {
    std::vector<std::string> out;
    for (auto item : py::reinterpret_borrow<py::dict>(d))
      out.push_back(value_text(item.first, flag) + "=" + value_text(item.second, flag));
    return out;
  };
  if (v.is_none()) return {};
  if (is_text(v) || is_number(v)) return {value_text(v, flag)};
  if (py::isinstance<py::dict>(v)) {
    std::vector<std::string> out = dict_items(v);
    if (one_flag) return {joined(out, ",")};
    return out;
  }
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    std::vector<std::string> out;
    for (py::handle x : v)
      out.push_back(py::isinstance<py::dict>(x) ? joined(dict_items(x), ",") : value_text(x, flag));
    return out;
  }
  throw std::invalid_argument(flag + ": expected a str, a dict or a list, not " + type_name(v));
}

std::optional<std::string> Keywords::list(const char* name) const {
  const py::handle v = value(name);
  if (v.is_none()) return std::nullopt;
  if (is_text(v)) return value_text(v, flag_name(name));
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    std::vector<std::string> parts;
    for (py::handle x : v) parts.push_back(value_text(x, flag_name(name)));
    return joined(parts, ",");
  }
  throw std::invalid_argument(flag_name(name) + ": expected a str or a list of str, not " +
                              type_name(v));
}

std::optional<double> Keywords::number(const char* name) const {
  const py::handle v = value(name);
  if (v.is_none()) return std::nullopt;
  if (!is_number(v))
    throw std::invalid_argument(flag_name(name) + ": expected a number, not " + type_name(v) +
                                " (" + py::repr(v).cast<std::string>() + ")");
  return py::float_(object(v)).cast<double>();
}

std::optional<long> Keywords::integer(const char* name) const {
  const py::handle v = value(name);
  if (v.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(v) || !py::hasattr(v, "__index__"))
    throw std::invalid_argument(flag_name(name) + ": expected a whole number, not " +
                                py::repr(v).cast<std::string>());
  const py::int_ i(object(v));
  if (i < py::int_(std::numeric_limits<long>::min()) ||
      i > py::int_(std::numeric_limits<long>::max()))
    throw std::invalid_argument(flag_name(name) + ": " + py::repr(i).cast<std::string>() +
                                " is out of range");
  return i.cast<long>();
}

std::optional<std::uint64_t> Keywords::count(const char* name) const {
  const py::handle v = value(name);
  if (v.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(v) || !py::hasattr(v, "__index__"))
    throw std::invalid_argument(flag_name(name) + ": expected a whole number >= 0, not " +
                                py::repr(v).cast<std::string>());
  const py::int_ i(object(v));
  if (i < py::int_(0) || i > py::int_(std::numeric_limits<std::uint64_t>::max()))
    throw std::invalid_argument(flag_name(name) + ": expected a whole number >= 0, not " +
                                py::repr(i).cast<std::string>());
  return i.cast<std::uint64_t>();
}

bool Keywords::flag(const char* name) const {
  const py::handle v = value(name);
  if (v.is_none()) return false;
  if (!py::isinstance<py::bool_>(v))
    throw std::invalid_argument(flag_name(name) + ": expected True or False, not " +
                                py::repr(v).cast<std::string>());
  return v.cast<bool>();
}

}  // namespace weilgen::python
