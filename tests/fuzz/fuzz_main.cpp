// A libFuzzer target: SKINMESH_FUZZ_TARGET names one of fuzz_input.hpp's
// targets; each input is written to a private folder and read from there.
#include "fuzz_input.hpp"

#include <cstdlib>
#include <filesystem>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const skinmesh::fuzz::FuzzTarget& target = skinmesh::fuzz::fuzz_target(SKINMESH_FUZZ_TARGET);
  static const std::string folder = [] {
    char pattern[] = "/tmp/skinmesh-fuzz-XXXXXX";
    if (!mkdtemp(pattern)) std::abort();
    static std::string made = pattern;
    std::atexit([] { std::filesystem::remove_all(made); });
    return made;
  }();
  skinmesh::fuzz::read_fuzz_input(target, data, size, folder);
  return 0;
}
