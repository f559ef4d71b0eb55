#pragma once

namespace weilgen {
inline constexpr const char* kVersion = "0.1.0";
}
