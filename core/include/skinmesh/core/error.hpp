// One way to fail on bad input: an InputError that names the file, the line
// (when there is one) and what was wrong. Thrown through input_error().
#pragma once

#include <stdexcept>
#include <string>

namespace skinmesh {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, long line, const std::string& message);
  const std::string& file() const { return file_; }
  long line() const { return line_; }  // 1-based; 0 when no line applies
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  long line_;
  std::string message_;
};

// Throws InputError; the text reads "FILE:LINE: MESSAGE" (or "FILE: MESSAGE").
[[noreturn]] void input_error(const std::string& file, long line, const std::string& message);

}  // namespace skinmesh
