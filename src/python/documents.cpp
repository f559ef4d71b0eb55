#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "binding.hpp"

namespace weilgen::python {

using nlohmann::json;

namespace {

// A rectangular nest of JSON arrays whose leaves are numbers or nulls.
struct NumericArray {
  std::vector<py::ssize_t> shape;
  std::vector<double> values;
  std::vector<std::int64_t> integers;
  bool integer = true;  // every leaf an integer that fits int64
  std::size_t leaf_depth = 0;
  bool leaf_depth_set = false;
};

bool collect(const json& j, std::size_t depth, NumericArray& a) {
  if (j.empty()) return false;  // an empty array has no type: it stays a list
  if (depth == a.shape.size())
    a.shape.push_back(static_cast<py::ssize_t>(j.size()));
  else if (a.shape[depth] != static_cast<py::ssize_t>(j.size()))
    return false;
  for (const json& x : j) {
    if (x.is_array()) {
      if (!collect(x, depth + 1, a)) return false;
      continue;
    }
    if (!x.is_number() && !x.is_null()) return false;
    if (!a.leaf_depth_set) {
      a.leaf_depth = depth;
      a.leaf_depth_set = true;
    } else if (a.leaf_depth != depth) {
      return false;
    }
    if (x.is_null()) {
      a.integer = false;
      a.values.push_back(std::numeric_limits<double>::quiet_NaN());
    } else if (x.is_number_float()) {
      a.integer = false;
      a.values.push_back(x.get<double>());
    } else if (x.is_number_unsigned() &&
               x.get<std::uint64_t>() >
                   static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      return false;  // no int64 holds it, and a double would round it: a list keeps it exact
    } else {
      a.integers.push_back(x.get<std::int64_t>());
      a.values.push_back(x.get<double>());
    }
  }
  return a.leaf_depth + 1 == a.shape.size();
}

template <typename T>
py::object make_array(const std::vector<py::ssize_t>& shape, const std::vector<T>& values) {
  py::array_t<T> out(shape);
  std::copy(values.begin(), values.end(), out.mutable_data());
  return std::move(out);
}

py::object plain_value(py::handle v) {
  if (py::isinstance<py::float_>(v)) {
    const double d = v.cast<double>();
    if (std::isnan(d)) return py::none();
    return py::float_(d);
  }
  if (py::isinstance<py::array>(v)) return plain_value(v.attr("tolist")());
  if (py::isinstance<py::dict>(v)) {
    py::dict out;
    for (auto item : py::reinterpret_borrow<py::dict>(v))
      out[item.first] = plain_value(item.second);
    return std::move(out);
  }
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    py::list out;
    for (py::handle x : v) out.append(plain_value(x));
    return std::move(out);
  }
  if (py::hasattr(v, "item") && py::hasattr(v, "dtype")) return plain_value(v.attr("item")());
  return py::reinterpret_borrow<py::object>(v);
}

using ErrorIndex = std::map<std::string, std::size_t>;

py::object convert(const json& j, const ErrorIndex& errors);

// An object's items, in the model's error order when every key is an error name.
py::dict object_dict(const json& j, const ErrorIndex& errors) {
  py::dict d;
  std::vector<std::pair<std::size_t, const std::string*>> order;
  for (const auto& item : j.items()) {
    const auto it = errors.find(item.key());
    if (it == errors.end()) {
      order.clear();
      break;
    }
    order.emplace_back(it->second, &item.key());
  }
  if (order.size() > 1) {
    std::sort(order.begin(), order.end());
    for (const auto& [index, key] : order) d[py::str(*key)] = convert(j.at(*key), errors);
    return d;
  }
  for (const auto& [key, value] : j.items()) d[py::str(key)] = convert(value, errors);
  return d;
}

py::object convert(const json& j, const ErrorIndex& errors) {
  switch (j.type()) {
    case json::value_t::null:
      return py::none();
    case json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case json::value_t::number_integer:
      return py::int_(j.get<std::int64_t>());
    case json::value_t::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case json::value_t::number_float:
      return py::float_(j.get<double>());
    case json::value_t::string:
      return py::str(j.get<std::string>());
    case json::value_t::object:
      return object_dict(j, errors);
    case json::value_t::array: {
      NumericArray a;
      if (collect(j, 0, a))
        return a.integer ? make_array(a.shape, a.integers) : make_array(a.shape, a.values);
      py::list l;
      for (const json& x : j) l.append(convert(x, errors));
      return std::move(l);
    }
    default:
      return py::none();  // binary and discarded values: no document holds them
  }
}

}  // namespace

py::object to_python(const json& j, const std::vector<std::string>& errors) {
  ErrorIndex index;
  for (std::size_t i = 0; i < errors.size(); ++i) index.emplace(errors[i], i);
  return convert(j, index);
}

void register_documents(py::module_& m) {
  m.def("plain", &plain_value, py::arg("document"),
        "The document with numpy arrays as lists and NaN as None: exactly what the CLI's --json "
        "writes, ready for json.dump.");
}

}  // namespace weilgen::python
