#include "weilgen/base/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace weilgen {

std::string temporary_path_for(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(dir, ec);
  return (dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()))).string();
}

void write_file_atomically(const std::string& path, const std::string& contents) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path tmp = temporary_path_for(path);
  std::error_code ec;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot write (" + std::strerror(errno) + ")");
    out << contents;
    out.flush();
    if (!out) {
      fs::remove(tmp, ec);
      throw std::runtime_error(path + ": write failed");
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(path + ": cannot replace (" + ec.message() + ")");
  }
}

void check_output_target(const std::string& path, const std::vector<std::string>& inputs,
                         const std::string& flag) {
  namespace fs = std::filesystem;
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument(flag + " " + path + ": " + why);
  };
  if (path.empty()) throw std::invalid_argument(flag + ": an empty path");
  std::error_code ec;
  if (fs::is_directory(path, ec)) fail("is a directory; give a file name");
  const fs::path canonical = fs::weakly_canonical(path, ec);
  for (const std::string& in : inputs) {
    std::error_code e1, e2;
    if (fs::equivalent(path, in, e1) || (!ec && fs::weakly_canonical(in, e2) == canonical && !e2))
      fail("is also an input (" + in + "); write the output to another file");
  }
  fs::path dir = fs::absolute(path, ec).parent_path();
  while (!dir.empty() && !fs::exists(dir, ec) && dir != dir.parent_path()) dir = dir.parent_path();
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) fail(dir.string() + " is not a directory");
  if (::access(dir.c_str(), W_OK) != 0) fail("cannot write in " + dir.string());
}

bool read_file(const std::string& path, std::string& contents) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  contents = ss.str();
  return true;
}

}  // namespace weilgen
