#include "model_cache.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/machine/model_key.hpp"

namespace weilgen::model_cache {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[9] = "WGMODEL1";
constexpr std::size_t kTrailer = 24;  // magic, payload size, FNV-1a of the payload

std::string octal(mode_t m) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(m & 07777));
  return buf;
}

void put64(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) s += static_cast<char>((v >> (8 * i)) & 0xff);
}

std::uint64_t get64(const std::string& s, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i)
    v = (v << 8) | static_cast<unsigned char>(s[at + static_cast<std::size_t>(i)]);
  return v;
}

[[noreturn]] void refuse(const std::string& dir, const std::string& what, const std::string& fix) {
  throw std::runtime_error("model cache " + dir + ": " + what +
                           "; weilgen loads compiled models (code that runs) only from a "
                           "directory of your own that no one else can write: " +
                           fix);
}

}  // namespace

void check_directory(const std::string& dir) {
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) {
    if (errno == ENOENT) return;
    refuse(dir, std::string("cannot inspect it (") + std::strerror(errno) + ")",
           "set WEILGEN_CACHE_DIR to another directory");
  }
  if (!S_ISDIR(st.st_mode))
    refuse(dir, "is not a directory", "remove it or set WEILGEN_CACHE_DIR to a directory");
  if (st.st_uid != ::geteuid())
    refuse(dir,
           "is owned by uid " + std::to_string(st.st_uid) + ", not by you (uid " +
               std::to_string(::geteuid()) + ")",
           "set WEILGEN_CACHE_DIR to a directory you own");
  if ((st.st_mode & (S_IWGRP | S_IWOTH)) != 0)
    refuse(dir, "is writable by group or others (mode " + octal(st.st_mode) + ")",
           "chmod 700 " + dir + " (or set WEILGEN_CACHE_DIR)");
  // An ancestor others can write without the sticky bit lets them swap the directory.
  fs::path p = fs::absolute(dir).parent_path();
  for (; !p.empty(); p = p.parent_path()) {
    if (::stat(p.c_str(), &st) == 0 && (st.st_mode & S_IWOTH) != 0 && (st.st_mode & S_ISVTX) == 0)
      refuse(dir,
             "its parent " + p.string() + " is writable by others without the sticky bit (mode " +
                 octal(st.st_mode) + ")",
             "set WEILGEN_CACHE_DIR to a directory in a protected place");
    if (p == p.root_path()) break;
  }
}

void create_directory(const std::string& dir) {
  std::error_code ec;
  const fs::path path(dir);
  if (!fs::exists(path, ec)) {
    if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
    if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST)
      throw std::runtime_error("cannot create the model cache " + dir + ": " +
                               std::strerror(errno));
  }
  check_directory(dir);
}

EntryState check_entry(const std::string& path, std::string& why) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return EntryState::Missing;
  if (S_ISLNK(st.st_mode) || !S_ISREG(st.st_mode) || st.st_uid != ::geteuid() ||
      (st.st_mode & (S_IWGRP | S_IWOTH)) != 0)
    throw std::runtime_error("model cache entry " + path +
                             " is not a regular file of yours that only you can write; "
                             "weilgen does not load it: remove it");
  std::string bytes;
  if (!read_file(path, bytes)) {
    why = "cannot be read";
    return EntryState::Damaged;
  }
  if (bytes.size() < kTrailer || bytes.compare(bytes.size() - kTrailer, 8, kMagic) != 0) {
    why = "has no intact trailer (truncated, or written by another version)";
    return EntryState::Damaged;
  }
  const std::size_t payload = bytes.size() - kTrailer;
  if (get64(bytes, payload + 8) != payload) {
    why = "is truncated or extended";
    return EntryState::Damaged;
  }
  if (fnv1a64(bytes.substr(0, payload)) != get64(bytes, payload + 16)) {
    why = "does not match its checksum (altered)";
    return EntryState::Damaged;
  }
  return EntryState::Intact;
}

void store_entry(const std::string& object, const std::string& path) {
  std::string bytes = object;
  bytes.append(kMagic, 8);
  put64(bytes, object.size());
  put64(bytes, fnv1a64(object));
  write_file_atomically(path, bytes, 0600);
}

}  // namespace weilgen::model_cache
