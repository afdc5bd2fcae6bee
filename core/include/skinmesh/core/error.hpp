// One exception family for everything skinmesh throws. Expected outcomes of
// the algorithms (a refinement over its budget, a guarantee not met, TetGen
// giving up) are not exceptions: they are statuses in the result structs.
//   Error          the base: catch it to catch anything skinmesh throws
//   InputError     bad input data: names the file, the line and what was wrong
//   ContractError  a caller broke a documented precondition (an option out of
//                  its range, an empty ball set)
//   OutputError    a file could not be written
#pragma once

#include <stdexcept>
#include <string>

namespace skinmesh {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class InputError : public Error {
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

class ContractError : public Error {
 public:
  using Error::Error;
};

class OutputError : public Error {
 public:
  using Error::Error;
};

// Throw through these. input_error's text reads "FILE:LINE: MESSAGE" (or
// "FILE: MESSAGE"); output_error's "PATH: MESSAGE".
[[noreturn]] void input_error(const std::string& file, long line, const std::string& message);
[[noreturn]] void contract_error(const std::string& message);
[[noreturn]] void output_error(const std::string& path, const std::string& message);

}  // namespace skinmesh
