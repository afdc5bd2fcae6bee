// Replays every input kept under tests/fuzz/inputs/<target>/ through the
// fuzz targets' reader (fuzz_input.hpp): hostile cases of the hostile-input
// issue and whatever the fuzzers found. Each must be read or refused with
// the project's error; another exception fails here, a crash ends the run.
#include "fuzz/fuzz_input.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

TEST_CASE("every kept fuzz input is read or refused with the project's error", "[fuzz][bad]") {
  char pattern[] = "/tmp/skinmesh-fuzz-replay-XXXXXX";
  REQUIRE(mkdtemp(pattern) != nullptr);
  long replayed = 0;
  for (const auto& target : skinmesh::fuzz::fuzz_targets()) {
    const fs::path folder = fs::path(SKINMESH_FUZZ_INPUTS) / target.name;
    long kept = 0;
    for (const auto& entry : fs::directory_iterator(folder)) {
      INFO(entry.path().string());
      std::ifstream in(entry.path(), std::ios::binary);
      std::ostringstream bytes;
      bytes << in.rdbuf();
      const std::string input = bytes.str();
      CHECK_NOTHROW(skinmesh::fuzz::read_fuzz_input(target, reinterpret_cast<const uint8_t*>(input.data()),
                                                    input.size(), pattern));
      ++kept;
    }
    INFO(target.name);
    CHECK(kept > 0);  // every reader has its hostile cases
    replayed += kept;
  }
  CHECK(replayed >= 14);
  fs::remove_all(pattern);
}
