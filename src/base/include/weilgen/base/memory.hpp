// Memory a run will need, checked before it allocates: a flag such as --samples 1000000000 is
// refused with an estimate instead of exhausting the machine (std::bad_alloc, or worse, the
// out-of-memory killer taking other processes with it).
#pragma once

#include <string>

namespace weilgen {

// This machine's physical memory in bytes (0 when unknown).
double physical_memory_bytes();

// "1.5 GB", "340 MB", "12 kB".
std::string format_bytes(double bytes);

// Throws std::invalid_argument "<what>: the run needs about 342 GB of memory, more than the
// 24 GB of this machine: <advice>" when `bytes` exceeds the physical memory.
void check_memory(double bytes, const std::string& what, const std::string& advice);

}  // namespace weilgen
