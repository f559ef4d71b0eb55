#include "weilgen/base/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace weilgen {

namespace {

std::string error_text(int err) { return std::strerror(err); }

// Opens a new temporary file; a stale one (a crashed run with the same pid) is replaced, and a
// symbolic link planted in its place is never followed.
int open_temporary(const std::string& tmp, unsigned mode) {
  for (int attempt = 0; attempt < 2; ++attempt) {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW,
                          static_cast<mode_t>(mode));
    if (fd >= 0 || errno != EEXIST) return fd;
    ::unlink(tmp.c_str());
  }
  return -1;
}

}  // namespace

std::string temporary_path_for(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(dir, ec);
  return (dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()))).string();
}

void write_file_atomically(const std::string& path, const std::string& contents, unsigned mode) {
  namespace fs = std::filesystem;
  const std::string tmp = temporary_path_for(path);
  const int fd = open_temporary(tmp, mode);
  if (fd < 0) throw std::runtime_error(path + ": cannot write (" + error_text(errno) + ")");
  std::size_t done = 0;
  while (done < contents.size()) {
    const ssize_t n = ::write(fd, contents.data() + done, contents.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw std::runtime_error(path + ": write failed (" + error_text(err) + ")");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw std::runtime_error(path + ": write failed (" + error_text(err) + ")");
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw std::runtime_error(path + ": cannot replace (" + error_text(err) + ")");
  }
  // The rename itself reaches the disk with the directory.
  const fs::path target(path);
  const std::string dir = target.has_parent_path() ? target.parent_path().string() : ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

bool read_file(const std::string& path, std::string& contents) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return false;  // e.g. a directory: opens, but reading fails
  contents = ss.str();
  return true;
}

std::string unreadable_reason(const std::string& path) {
  struct stat st {};
  if (path.empty()) return "no file name given";
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return "no such file";
    return error_text(errno);
  }
  if (S_ISDIR(st.st_mode)) return "is a directory, not a file";
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return error_text(errno);
  ::close(fd);
  return "";
}

}  // namespace weilgen
