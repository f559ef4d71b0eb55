// Writes files so that readers never see a partial file and failures leave the old one intact:
// write to a temporary file in the same directory, then rename over the target.
#pragma once

#include <string>

namespace weilgen {

// Throws std::runtime_error naming the path on failure.
void write_file_atomically(const std::string& path, const std::string& contents);
// The temporary path next to `path` that an atomic write goes through
// ("<dir>/.<name>.tmp<pid>"); creates the directory. Rename it over `path` when complete.
std::string temporary_path_for(const std::string& path);
// Reads a whole file; returns false when it cannot be opened.
bool read_file(const std::string& path, std::string& contents);

}  // namespace weilgen
