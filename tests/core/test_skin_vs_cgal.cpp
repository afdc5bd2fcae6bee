// The skin function against CGAL's Skin_surface_3 (Kruithof-Vegter): a third,
// fully independent implementation of the same surface.
#include "test_support.hpp"

#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Skin_surface_3.h>
#include <CGAL/Skin_surface_traits_3.h>

#include <catch2/catch.hpp>

using namespace skinmesh;

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Traits = CGAL::Skin_surface_traits_3<K>;
using CgalSkin = CGAL::Skin_surface_3<Traits>;

void check_signs_against_cgal(const std::string& path, int count, unsigned seed) {
  const double s = 0.5;
  const Molecule m = read_molecule(path);
  const auto balls = balls_from_molecule(m, s, WeightConvention::GrowBySkin);
  std::vector<K::Weighted_point_3> wp;
  for (const Ball& b : balls) wp.emplace_back(K::Point_3(b.center.x(), b.center.y(), b.center.z()), b.weight);
  // grow_balls = false: the weights are already r^2/s.
  const CgalSkin cgal(wp.begin(), wp.end(), s, false);
  const SkinComplex sc = build_skin_complex(balls, {s});
  long compared = 0, mismatches = 0, near_zero = 0;
  for (const Eigen::Vector3d& x : test::sample_near_balls(balls, s, count, 1.5, seed)) {
    const double f = sc.value(x);
    if (std::abs(f) < 1e-9) {
      ++near_zero;  // too close to the skin for a sign comparison of two float codes
      continue;
    }
    const CGAL::Sign sign = cgal.sign(K::Point_3(x.x(), x.y(), x.z()));
    ++compared;
    if ((f < 0) != (sign == CGAL::NEGATIVE)) ++mismatches;
  }
  INFO(path << ": compared " << compared << ", near zero " << near_zero);
  CHECK(compared >= count * 99 / 100);
  CHECK(mismatches == 0);
}
}  // namespace

TEST_CASE("skin sign agrees with CGAL Skin_surface_3 on pept", "[skin][cgal]") {
  check_signs_against_cgal(test::data_file("pept.pdb"), 3000, 21);
}

TEST_CASE("skin sign agrees with CGAL Skin_surface_3 on 3al1", "[skin][cgal]") {
  check_signs_against_cgal(test::data_file("3al1.pdb"), 3000, 22);
}

TEST_CASE("skin sign agrees with CGAL Skin_surface_3 on 1ubi", "[skin][cgal]") {
  check_signs_against_cgal(test::data_file("1ubi.pdb"), 3000, 23);
}
