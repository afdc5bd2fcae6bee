// skin_topology's own classification of the alpha complex at alpha = 0
// against CGAL's Fixed_alpha_shape_3 of the same balls (the reference in
// tests/reference): random sets, tangent and cospherical balls, flat sets,
// balls inside others, and the molecules of data/.
#include "cgal_reference.hpp"
#include "test_support.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_topology.hpp"

#include <catch2/catch.hpp>

#include <random>
#include <string>

using namespace skinmesh;

namespace {

// Four balls of no body far around the origin: CGAL's alpha shape needs a
// three-dimensional triangulation, and they take no part in K.
const std::vector<Ball> kFar = {{Eigen::Vector3d(1e3, 1e3, 1e3), -1.0},
                                {Eigen::Vector3d(1e3, -1e3, -1e3), -1.0},
                                {Eigen::Vector3d(-1e3, 1e3, -1e3), -1.0},
                                {Eigen::Vector3d(-1e3, -1e3, 1e3), -1.0}};

// Both counts as text (components, voids and Euler characteristic), so that
// a failure shows them.
std::string counted(const std::vector<Ball>& balls) { return skin_topology(balls).text(); }
std::string reference(const std::vector<Ball>& balls) { return test::cgal_alpha_shape_topology(balls, kFar).text(); }

// n balls in a cube whose side grows with n, of weights 0.3 to `heaviest`:
// from apart to crowded, some enclosing voids.
std::vector<Ball> random_set(int n, double heaviest, std::mt19937& random) {
  const double box = 2.0 + 0.15 * n;
  std::uniform_real_distribution<double> at(-box, box), weight(0.3, heaviest);
  std::vector<Ball> balls;
  for (int i = 0; i < n; ++i) balls.push_back({Eigen::Vector3d(at(random), at(random), at(random)), weight(random)});
  return balls;
}

}  // namespace

TEST_CASE("skin topology classifies the alpha complex as CGAL's alpha shape does", "[topology]") {
  SECTION("random sets, from apart to crowded, with voids") {
    std::mt19937 random(11);
    long with_voids = 0, with_handles = 0;
    for (int set = 0; set < 300; ++set) {
      const std::vector<Ball> balls = random_set(4 + set % 60, set % 3 == 0 ? 12.0 : 4.0, random);
      INFO("set " << set);
      const SkinTopology topology = skin_topology(balls);
      REQUIRE(topology.text() == reference(balls));
      with_voids += topology.voids > 0;
      with_handles += topology.euler < 2 * topology.components;
    }
    // The sets reach what the classification must get right.
    CHECK(with_voids > 0);
    CHECK(with_handles > 0);
  }
  SECTION("tangent and cospherical balls on a lattice, some taken out") {
    std::mt19937 random(5);
    for (double weight : {1.0, 2.0, 3.0}) {  // spacing 2: 1 is tangent, 2 and 3 meet along the lattice's faces and cells
      for (int drop = 0; drop < 4; ++drop) {
        std::vector<Ball> balls;
        std::bernoulli_distribution kept(1.0 - 0.1 * drop);
        for (int x = 0; x < 5; ++x)
          for (int y = 0; y < 5; ++y)
            for (int z = 0; z < 5; ++z)
              if (kept(random)) balls.push_back({Eigen::Vector3d(2 * x, 2 * y, 2 * z), weight});
        INFO("weight " << weight << ", drop " << drop);
        CHECK(counted(balls) == reference(balls));
      }
    }
  }
  SECTION("flat sets and balls inside others") {
    std::vector<Ball> ring, line;
    for (int k = 0; k < 12; ++k) ring.push_back({Eigen::Vector3d(6 * std::cos(k * M_PI / 6), 6 * std::sin(k * M_PI / 6), 0), 4.0});
    for (int k = 0; k < 6; ++k) line.push_back({Eigen::Vector3d(1.5 * k, 0, 0), 1.0 + 0.5 * k});
    CHECK(counted(ring) == reference(ring));
    CHECK(counted(line) == reference(line));
    // A ball wholly inside a larger one, one whose centre lies in its
    // neighbour's power cell, and one of no body.
    const std::vector<Ball> nested = {{Eigen::Vector3d::Zero(), 16.0},
                                      {Eigen::Vector3d(1, 0, 0), 1.0},
                                      {Eigen::Vector3d(4.5, 0, 0), 2.0},
                                      {Eigen::Vector3d(0, 9, 0), -2.0}};
    CHECK(counted(nested) == reference(nested));
  }
  SECTION("the molecules of data/") {
    for (const char* name : {"pept.pdb", "1ubi.pdb", "3al1.pdb", "1ejg.pdb"}) {
      INFO(name);
      const std::vector<Ball> balls = balls_from_molecule(read_molecule(test::data_file(name)), 0.5);
      CHECK(counted(balls) == reference(balls));
    }
  }
}

TEST_CASE("a complex built with its topology counts what skin_topology counts, and a moved one forgets it", "[topology]") {
  SkinComplexOptions counting;
  counting.count_topology = true;
  std::mt19937 random(23);
  for (int set = 0; set < 100; ++set) {
    const std::vector<Ball> balls = random_set(4 + set % 50, set % 3 == 0 ? 12.0 : 4.0, random);
    INFO("set " << set);
    const SkinComplex complex = build_skin_complex(balls, counting);
    REQUIRE(complex.topology().has_value());
    CHECK(complex.topology()->text() == counted(balls));
  }
  for (const char* name : {"pept.pdb", "1ubi.pdb", "3al1.pdb", "1ejg.pdb"}) {
    INFO(name);
    const std::vector<Ball> balls = balls_from_molecule(read_molecule(test::data_file(name)), 0.5);
    const SkinComplex complex = build_skin_complex(balls, counting);
    REQUIRE(complex.topology().has_value());
    CHECK(complex.topology()->text() == counted(balls));
    CHECK_FALSE(build_skin_complex(balls).topology().has_value());  // not asked
    std::vector<Ball> moved = balls;
    moved[0].center.x() += 0.01;
    CHECK_FALSE(complex.with_balls(moved).topology().has_value());
  }
  // Not counted where the triangulation is flat, or a ball has no body.
  std::vector<Ball> ring;
  for (int k = 0; k < 12; ++k) ring.push_back({Eigen::Vector3d(6 * std::cos(k * M_PI / 6), 6 * std::sin(k * M_PI / 6), 0), 4.0});
  CHECK_FALSE(build_skin_complex(ring, counting).topology().has_value());
  std::vector<Ball> with_empty = {{Eigen::Vector3d::Zero(), 4.0}, {Eigen::Vector3d(3, 0, 0), 4.0},
                                  {Eigen::Vector3d(0, 3, 0), 4.0}, {Eigen::Vector3d(0, 0, 3), -1.0}};
  CHECK_FALSE(build_skin_complex(with_empty, counting).topology().has_value());
}
