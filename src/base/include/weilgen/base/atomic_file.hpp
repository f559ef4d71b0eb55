// Writes files so that readers never see a partial file and failures leave the old one intact:
// write to a temporary file in the same directory, then rename over the target.
#pragma once

#include <string>
#include <vector>

namespace weilgen {

// Throws std::runtime_error naming the path on failure.
void write_file_atomically(const std::string& path, const std::string& contents);
// The temporary path next to `path` that an atomic write goes through
// ("<dir>/.<name>.tmp<pid>"); creates the directory. Rename it over `path` when complete.
std::string temporary_path_for(const std::string& path);
// Checks an output path before any work is done: not empty, not a directory, not the same file
// as any of `inputs` (also through links or another spelling of the path), and its nearest
// existing directory writable. Throws std::invalid_argument "<flag> <path>: why" (exit 2).
void check_output_target(const std::string& path, const std::vector<std::string>& inputs,
                         const std::string& flag);
// Reads a whole file; returns false when it cannot be opened.
bool read_file(const std::string& path, std::string& contents);

}  // namespace weilgen
