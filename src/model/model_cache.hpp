// Internal to the model layer: the cache of compiled models (docs/runtime-models.md).
//
// Shared objects run code when they are loaded (their constructors run inside dlopen, before any
// key check), so a cache entry is loaded only from a directory that this user owns and no one
// else can write, and only when its content is what weilgen wrote: every entry ends with a
// trailer (magic, size, FNV-1a hash of the object) checked before dlopen. A damaged entry
// (truncated by a full disk or a crash, altered) is discarded and compiled again.
#pragma once

#include <string>

namespace weilgen::model_cache {

// Checks an existing cache directory: a directory owned by this user (effective uid), not
// writable by group or others, and no ancestor writable by others without the sticky bit.
// Throws std::runtime_error saying what is wrong and how to fix it. A missing directory is fine.
void check_directory(const std::string& dir);
// Creates the directory (mode 0700, parents as needed) when missing, then checks it.
void create_directory(const std::string& dir);

enum class EntryState { Missing, Intact, Damaged };
// The state of an entry; `why` says what is wrong with a damaged one. An entry owned by another
// user or writable by others is refused (std::runtime_error).
EntryState check_entry(const std::string& path, std::string& why);
// Writes the compiled object `object` (its bytes) as the entry `path`: trailer appended, mode
// 0600, fsync, rename (base/atomic_file).
void store_entry(const std::string& object, const std::string& path);

}  // namespace weilgen::model_cache
