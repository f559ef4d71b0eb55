// Where a problem in an input file is, and the exception that reports it. Every reader (machine
// files, tolerance files, measurement CSV) throws InputError; the CLI prints what() and exits 3.
#pragma once

#include <stdexcept>
#include <string>

namespace weilgen {

struct SourceLoc {
  std::string file;
  int line = 0;             // 1-based; 0 = unknown
  int column = 0;           // 1-based; 0 = unknown
  std::string str() const;  // "file:line:column"
};

// Bad input in a file. what() is "file:line:column: message".
class InputError : public std::runtime_error {
 public:
  InputError(const SourceLoc& loc, const std::string& message);
  const SourceLoc& loc() const { return loc_; }
  const std::string& message() const { return message_; }

 private:
  SourceLoc loc_;
  std::string message_;
};

}  // namespace weilgen
