#include "skinmesh/core/error.hpp"

namespace skinmesh {

namespace {
std::string format_input_error(const std::string& file, long line, const std::string& message) {
  std::string where = file.empty() ? std::string("<input>") : file;
  if (line > 0) where += ":" + std::to_string(line);
  return where + ": " + message;
}
}  // namespace

InputError::InputError(std::string file, long line, const std::string& message)
    : Error(format_input_error(file, line, message)), file_(std::move(file)), line_(line), message_(message) {}

void input_error(const std::string& file, long line, const std::string& message) {
  throw InputError(file, line, message);
}

void contract_error(const std::string& message) { throw ContractError(message); }

void output_error(const std::string& path, const std::string& message) {
  throw OutputError(path.empty() ? message : path + ": " + message);
}

}  // namespace skinmesh
