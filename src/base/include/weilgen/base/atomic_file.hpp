// Writes files so that readers never see a partial file and failures leave the old one intact:
// write to a temporary file in the same directory, flush it to disk, then rename over the target.
// Reads input files with a message that says why one cannot be read.
#pragma once

#include <string>
#include <vector>

namespace weilgen {

// Throws std::runtime_error naming the path on failure. The file is fsync'ed before the rename
// (a crash never leaves an empty file under the target's name) and the directory after it. New
// files get `mode` (less the umask): 0666 like any program's output, 0600 for private files.
void write_file_atomically(const std::string& path, const std::string& contents,
                           unsigned mode = 0666);
// The temporary path next to `path` that an atomic write goes through
// ("<dir>/.<name>.tmp<pid>"); creates the directory. Rename it over `path` when complete.
std::string temporary_path_for(const std::string& path);
// Reads a whole file; returns false when it cannot be opened.
bool read_file(const std::string& path, std::string& contents);
// Why `path` cannot be read as an input file, or "" when it can be opened: "no such file",
// "is a directory", "permission denied", ...
std::string unreadable_reason(const std::string& path);

}  // namespace weilgen
