// Content keys of compiled models. A model is identified by the text of its machine file, the
// algebra order and the weilgen version: the same three always generate the same header, so a
// built-in model or a cached shared object with the same key can stand in for generating and
// compiling again. Header-only: the machine loader (which has no runtime dependency) uses it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "weilgen/base/version.hpp"

namespace weilgen {

// 64-bit FNV-1a: a stable, platform-independent hash (not cryptographic; a cache key only).
inline std::uint64_t fnv1a64(const std::string& bytes, std::uint64_t seed = 0xcbf29ce484222325ULL) {
  std::uint64_t h = seed;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

inline std::string hex64(std::uint64_t v) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(v));
  return hex;
}

// 16 hex digits from the machine file's text hash, the order and the weilgen version.
inline std::string model_key(std::uint64_t source_hash, int order) {
  return hex64(
      fnv1a64(hex64(source_hash) + "|order=" + std::to_string(order) + "|weilgen=" + kVersion));
}

}  // namespace weilgen
