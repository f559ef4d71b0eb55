#include "weilgen/base/output_paths.hpp"

#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace weilgen {

namespace fs = std::filesystem;

namespace {

std::string name_of(const PathArg& p) { return p.flag.empty() ? "'" + p.path + "'" : p.flag; }

// The same file: one inode when both exist, else the same canonical path.
bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec) && !ec;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return ca == cb;
}

// An output can be written: not a directory, and its nearest existing ancestor is a writable
// directory (write_file_atomically creates the missing ones).
void check_writable(const PathArg& out) {
  std::error_code ec;
  if (fs::is_directory(out.path, ec))
    throw std::invalid_argument(out.flag + ": '" + out.path + "' is a directory; give a file name");
  fs::path dir = fs::absolute(out.path, ec).parent_path();
  while (!dir.empty() && !fs::exists(dir, ec) && dir != dir.root_path()) dir = dir.parent_path();
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw std::invalid_argument(out.flag + ": '" + out.path + "': " + dir.string() +
                                " is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw std::invalid_argument(out.flag + ": '" + out.path + "': cannot write into " +
                                dir.string() + " (" + std::generic_category().message(errno) + ")");
}

}  // namespace

void check_output_paths(const std::vector<PathArg>& inputs, const std::vector<PathArg>& outputs) {
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    const PathArg& out = outputs[o];
    if (out.path.empty()) continue;
    for (const PathArg& in : inputs) {
      if (in.path.empty() || !same_file(in.path, out.path)) continue;
      throw std::invalid_argument(out.flag + ": '" + out.path + "' is the input " + name_of(in) +
                                  (in.flag.empty() ? "" : " ('" + in.path + "')") +
                                  "; writing it would destroy the input: choose another file");
    }
    for (std::size_t p = 0; p < o; ++p)
      if (!outputs[p].path.empty() && same_file(outputs[p].path, out.path))
        throw std::invalid_argument(out.flag + ": '" + out.path + "' is also the output of " +
                                    outputs[p].flag + ": choose another file");
    check_writable(out);
  }
}

void check_output_dir(const std::vector<PathArg>& inputs, const PathArg& dir) {
  if (dir.path.empty()) return;
  std::error_code ec;
  for (const PathArg& in : inputs)
    if (!in.path.empty() && same_file(in.path, dir.path))
      throw std::invalid_argument(dir.flag + ": '" + dir.path + "' is the input " + name_of(in) +
                                  ": choose another directory");
  if (fs::exists(dir.path, ec) && !fs::is_directory(dir.path, ec))
    throw std::invalid_argument(dir.flag + ": '" + dir.path + "' is a file, not a directory");
  check_writable({dir.flag, (fs::path(dir.path) / "x").string()});
}

}  // namespace weilgen
