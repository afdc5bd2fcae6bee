#include "reader_detail.hpp"

#include "skinmesh/core/error.hpp"

#include <zlib.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/stat.h>

namespace skinmesh::detail {

namespace {

[[noreturn]] void too_large(const std::string& path, long long max_bytes, const char* what) {
  input_error(path, 0, std::string(what) + " more than " + std::to_string(max_bytes) +
                           " bytes of text, the limit for a molecule file (raise ReadOptions::max_bytes)");
}

}  // namespace

std::string read_file_text(const std::string& path, long long max_bytes) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0)
    input_error(path, 0, std::string("cannot open file: ") + std::strerror(errno));
  if (S_ISDIR(info.st_mode)) input_error(path, 0, "is a directory, not a molecule file");
  // A device or a pipe (/dev/zero) can be read for ever.
  if (!S_ISREG(info.st_mode)) input_error(path, 0, "is not a regular file");
  if (info.st_size > max_bytes) too_large(path, max_bytes, "holds");

  std::ifstream probe(path, std::ios::binary);
  if (!probe) input_error(path, 0, std::string("cannot open file: ") + std::strerror(errno));
  unsigned char magic[2] = {0, 0};
  probe.read(reinterpret_cast<char*>(magic), 2);
  const bool gzipped = probe.gcount() == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
  probe.close();

  std::string text;
  if (gzipped) {
    gzFile file = gzopen(path.c_str(), "rb");
    if (!file) input_error(path, 0, "cannot open gzip file");
    char buffer[1 << 16];
    int n = 0;
    while ((n = gzread(file, buffer, sizeof buffer)) > 0) {
      text.append(buffer, static_cast<size_t>(n));
      if (static_cast<long long>(text.size()) > max_bytes) {
        gzclose(file);
        too_large(path, max_bytes, "inflates to");
      }
    }
    int code = 0;
    const char* message = gzerror(file, &code);
    const bool failed = n < 0 || (code != Z_OK && code != Z_STREAM_END);
    const std::string why = failed && message ? message : "";
    gzclose(file);
    if (failed) input_error(path, 0, "corrupt gzip data: " + why);
  } else {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream all;
    all << in.rdbuf();
    text = all.str();
  }
  // A UTF-8 byte-order mark (editors on Windows write one) is no part of
  // the first record: left in, it hid the first ATOM line from every reader.
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    input_error(path, 0, "file is empty");
  return text;
}

bool parse_finite_double(const std::string& field, double& value) {
  const size_t first = field.find_first_not_of(" \t");
  if (first == std::string::npos) return false;
  const size_t last = field.find_last_not_of(" \t\r");
  const std::string trimmed = field.substr(first, last - first + 1);
  char* end = nullptr;
  errno = 0;
  value = std::strtod(trimmed.c_str(), &end);
  if (end != trimmed.c_str() + trimmed.size() || errno == ERANGE) return false;
  return std::isfinite(value);
}

bool is_water_residue(const std::string& name) {
  static const char* const waters[] = {"HOH", "WAT", "H2O", "DOD", "D2O", "TIP", "TIP3",
                                       "TIP4", "TIP5", "SOL", "SPC", "T3P", "T4P"};
  for (const char* w : waters)
    if (name == w) return true;
  return false;
}

}  // namespace skinmesh::detail
