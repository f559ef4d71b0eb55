#include "effects.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "weilgen/base/text.hpp"
#include "weilgen/machine/iso_names.hpp"

namespace weilgen::gap_detail {

std::vector<Candidate> effect_candidates(const EffectContext& ctx,
                                         const std::vector<std::string>& names) {
  std::vector<Candidate> out;
  for (const std::string& n : names) {
    if (n == "thermal_drift")
      add_thermal(ctx, out), add_thermal_sensors(ctx, out);
    else if (n == "reversal")
      add_reversal(ctx, out);
    else if (n == "periodic")
      add_periodic(ctx, out);
    else if (n == "pdge_shape")
      add_pdge_shape(ctx, out);
    else if (n == "higher_order")
      add_higher_order(ctx, out);
    else if (n == "missing_error")
      add_missing_error(ctx, out);
    else if (n == "tool_offset")
      add_tool_offset(ctx, out);
    else if (n == "setup")
      add_setup(ctx, out);
    else
      throw std::invalid_argument("--effects: unknown effect '" + n +
                                  "' (the library: " + join(gap_effect_names()) + ")");
  }
  return out;
}

}  // namespace weilgen::gap_detail
