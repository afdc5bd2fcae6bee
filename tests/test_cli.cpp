// The skinmesh command: exit codes and messages a user sees.
#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cstdio>
#include <sys/wait.h>

namespace {

struct Run {
  int code;
  std::string output;  // stdout and stderr together
};

Run run(const std::string& args) {
  const std::string command = std::string(SKINMESH_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string output;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

}  // namespace

TEST_CASE("skinmesh info reports atoms, radii and the complex", "[cli]") {
  const Run r = run("info " + skinmesh::test::data_file("pept.pdb"));
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("atoms read:     107") != std::string::npos);
  CHECK(r.output.find("tetrahedra") != std::string::npos);
  CHECK(r.output.find("hidden balls:   0") != std::string::npos);
}

TEST_CASE("skinmesh info --json is machine-readable", "[cli]") {
  const Run r = run("info --json " + skinmesh::test::shared_pdb("2k39_3models.pdb") + " --all-models");
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.front() == '[');
  CHECK(r.output.find("\"models_in_file\": 3") != std::string::npos);
  CHECK(r.output.find("\"tetrahedron\":") != std::string::npos);
}

TEST_CASE("skinmesh info on bad input: message names the file, non-zero exit", "[cli][bad]") {
  const Run missing = run("info /nonexistent/file.pdb");
  CHECK(missing.code == 2);
  CHECK(missing.output.find("/nonexistent/file.pdb") != std::string::npos);
  skinmesh::test::TempFile nan("nan.xyzr", "0 0 0 1.5\n1 nan 0 1.5\n");
  const Run bad = run("info " + nan.path());
  CHECK(bad.code == 2);
  CHECK(bad.output.find(nan.path() + ":2:") != std::string::npos);
  const Run usage = run("info");
  CHECK(usage.code != 0);
}

TEST_CASE("skinmesh info runs on every shared PDB entry", "[cli]") {
  for (const char* name : {"pept.pdb", "3al1.pdb", "1ubi.pdb", "1ejg.pdb", "1hpv.pdb", "3mht.pdb",
                           "2k39_3models.pdb"}) {
    const Run r = run("--quiet info " + skinmesh::test::shared_pdb(name));
    INFO(name << "\n" << r.output);
    CHECK(r.code == 0);
    CHECK(r.output.find("mixed cells:") != std::string::npos);
  }
}
