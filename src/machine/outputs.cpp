#include "weilgen/machine/outputs.hpp"

#include <stdexcept>

#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"

namespace weilgen {

const std::vector<OutputId>& all_outputs() {
  static const std::vector<OutputId> all = {OutputId::Dx, OutputId::Dy, OutputId::Dz, OutputId::Da,
                                            OutputId::Db, OutputId::Dc, OutputId::Dp};
  return all;
}

const char* output_name(OutputId id) {
  switch (id) {
    case OutputId::Dx:
      return "dx";
    case OutputId::Dy:
      return "dy";
    case OutputId::Dz:
      return "dz";
    case OutputId::Da:
      return "da";
    case OutputId::Db:
      return "db";
    case OutputId::Dc:
      return "dc";
    case OutputId::Dp:
      return "dp";
  }
  return "?";
}

bool output_is_angle(OutputId id) {
  return id == OutputId::Da || id == OutputId::Db || id == OutputId::Dc;
}

const char* output_unit(OutputId id) { return output_is_angle(id) ? "rad" : "mm"; }

OutputId parse_output(const std::string& name) {
  const std::string n = lower(trim(name));
  std::vector<std::string> names;
  for (OutputId id : all_outputs()) {
    if (n == output_name(id)) return id;
    names.push_back(output_name(id));
  }
  throw std::invalid_argument("unknown output \"" + name + "\" (expected " + join(names) + ")");
}

const char* measured_unit(std::size_t output) { return output < 3 ? "µm" : "µrad"; }

const std::array<const char*, kNumDeviationOutputs> kDeviationColumns = {
    "dx_um", "dy_um", "dz_um", "da_urad", "db_urad", "dc_urad"};

}  // namespace weilgen
