// Linked coordinates, derived quantities and the output transform of a machine description
// (machines/README.md, "Parallel chains"): what their names refer to, the order they are
// evaluated in, and the checks the loader runs on them. Shared by the loader, the exact numeric
// chain and the generator, so that all three read the constructs the same way.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"

namespace weilgen {

// What an identifier of a link, derived or output expression names.
struct NameRef {
  enum class Kind { Parameter, Coordinate, PointComponent, DirectionComponent, Derived };
  Kind kind = Kind::Parameter;
  int index = -1;      // parameter, body (coordinate), point, direction or derived index
  int component = -1;  // PointComponent, DirectionComponent: 0, 1, 2 for .x, .y, .z
};

// Resolves `name` (`pi` excluded: the parser makes it a number). Derived quantities with an index
// >= `derived_before` are not visible (evaluation is in file order). Throws std::invalid_argument
// with a message naming what is known.
NameRef resolve_name(const Description& desc, const std::string& name, std::size_t derived_before);

// Linked joints (body indices) ordered so that each follows the linked joints its expression uses.
std::vector<int> link_order(const Description& desc);

// Adds each linked coordinate's value (in its unit) to `values`, which must hold the parameters
// and the independent coordinates (in their units).
void resolve_links(const Description& desc, std::map<std::string, double>& values);

// Checks links (names, cycles), derived quantities (names, file order, nominal divisors that are
// non-zero over the travel range of the coordinates they use) and the output transform, and sets
// Derived::nominal. Throws InputError at the offending entry.
void check_derived(Description& desc);

}  // namespace weilgen
