#include "effects.hpp"

#include <algorithm>
#include <stdexcept>

#include "weilgen/base/text.hpp"

namespace weilgen::gap_detail {

namespace {

using Builder = void (*)(const EffectContext&, std::vector<Candidate>&);

struct LibraryEntry {
  GapEffectInfo info;
  std::vector<Builder> builders;  // each appends its candidate when the data allow it
};

// The effect library in report order (docs/gap.md, "Effect library"). Adding an effect is one
// row here and its file effect_<name>.cpp (docs/architecture.md, "An effect to the gap library").
const std::vector<LibraryEntry>& library() {
  static const std::vector<LibraryEntry> entries = {
      {{"thermal_drift", true,
        "a growth with time or temperature (lagged), fixed in the tool's or the machine's frame, "
        "and the linear axes' scales; several sensors as one ridge model"},
       {add_thermal, add_thermal_sensors}},
      {{"reversal", false, "a backlash of an axis with a direction of travel"}, {add_reversal}},
      {{"periodic", false, "a periodic shape of one motion error of one axis (pitch, period)"},
       {add_periodic}},
      {{"pdge_shape", false, "a bump or a higher-degree shape of one motion error of one axis"},
       {add_pdge_shape}},
      {{"higher_order", false, "products of errors: the exact kinematics refitted per split"},
       {add_higher_order}},
      {{"missing_error", false, "an ISO 230-1 error the machine file lacks"}, {add_missing_error}},
      {{"tool_offset", false, "a tool length other than the model's"}, {add_tool_offset}},
      {{"setup", false, "the measuring set-up: an instrument's scale, a ballbar's length"},
       {add_setup}},
  };
  return entries;
}

const LibraryEntry& entry(const std::string& name) {
  for (const LibraryEntry& e : library())
    if (e.info.name == name) return e;
  throw std::invalid_argument("--effects: unknown effect '" + name +
                              "' (the library: " + join(gap_effect_names()) + ")");
}

}  // namespace

std::vector<Candidate> effect_candidates(const EffectContext& ctx,
                                         const std::vector<std::string>& names) {
  std::vector<Candidate> out;
  for (const std::string& n : names)
    for (Builder add : entry(n).builders) add(ctx, out);
  return out;
}

bool effect_repeatable(const std::string& name) { return entry(name).info.repeatable; }

}  // namespace weilgen::gap_detail

namespace weilgen {

const std::vector<GapEffectInfo>& gap_effects() {
  static const std::vector<GapEffectInfo> infos = [] {
    std::vector<GapEffectInfo> v;
    for (const auto& e : gap_detail::library()) v.push_back(e.info);
    return v;
  }();
  return infos;
}

const std::vector<std::string>& gap_effect_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const GapEffectInfo& e : gap_effects()) v.push_back(e.name);
    return v;
  }();
  return names;
}

}  // namespace weilgen
