// Topology events ahead of time (eq. 18: every cell's size is quadratic in t)
// and the alignment of a target onto its source.
#include "test_support.hpp"
#include "two_balls.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/events.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

using namespace skinmesh;

TEST_CASE("every overlay cell's size is the quadratic fitted at three frames", "[morph][events]") {
  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m2 = test::centred_model(test::data_file("2k39_3models.pdb"), 2);
  const auto live = live_pairs(m1, m2);
  const SkinComplex middle = build_skin_complex(interpolated_balls(m1, m2, live, 0.5), {0.5});
  const std::vector<CellSize> sizes = cell_sizes(middle, m1, m2, live);
  REQUIRE(sizes.size() == middle.cells().size());
  long off = 0, checked = 0, other = 0;
  for (double t : {0.1, 0.4, 0.9}) {
    const SkinComplex frame = middle.with_balls(interpolated_balls(m1, m2, live, t));
    for (size_t c = 0; c < sizes.size(); ++c) {
      if (!sizes[c].overlay_cell || frame.cells()[c].degenerate) {
        ++other;
        continue;
      }
      const double r2 = frame.cells()[c].R2;
      // Relative 1e-5: a nearly flat tetrahedron's centre is ill-conditioned
      // (measured: 1e-6 relative on one of 2k39 with R2 = 3.6e9 A^2).
      off += std::abs(sizes[c].at(t) - r2) > 1e-5 * std::max(1.0, std::abs(r2));
      ++checked;
    }
  }
  INFO(off << " of " << checked << " overlay cell sizes off the quadratic; " << other << " other simplices");
  CHECK(off == 0);
  CHECK(checked > other);
}

TEST_CASE("the event where two skins join is found ahead of time", "[morph][events]") {
  const test::TwoBallMorph two;
  const auto live = live_pairs(two.source, two.target);
  const SkinComplex middle = build_skin_complex(interpolated_balls(two.source, two.target, live, 0.5), {0.5});
  const std::vector<TopologyEvent> events = topology_events(cell_sizes(middle, two.source, two.target, live));
  REQUIRE_FALSE(events.empty());
  // The oracle, blind to cells: the skin is split just before the first
  // event and joined just after.
  const MorphOracle oracle(two.source, two.target, 0.5);
  auto joined = [&](double t) { return two.joined(oracle, t, 400); };
  const double first = events.front().t;
  INFO("first event at t = " << first);
  // It is a critical point of the skin: the cone's apex lies in its cell.
  const std::vector<TopologyEvent> critical =
      critical_events(events, cell_sizes(middle, two.source, two.target, live), middle, live, oracle);
  REQUIRE_FALSE(critical.empty());
  CHECK(critical.front().t == first);
  CHECK_FALSE(joined(first - 1e-3));
  CHECK(joined(first + 1e-3));
}

TEST_CASE("alignment: Kabsch recovers a rigid motion, centroid otherwise", "[morph][alignment]") {
  const Molecule source = read_molecule(test::data_file("1ubi.pdb"));
  RigidMotion motion;
  motion.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  motion.translation = Eigen::Vector3d(30, -12, 5);
  const Molecule target = moved(source, motion);

  const Alignment k = align(source, target, AlignmentMethod::automatic);
  CHECK(k.used == AlignmentMethod::kabsch);
  CHECK(k.matched == static_cast<long>(source.atoms.size()));
  CHECK(k.rmsd <= 1e-9);
  for (size_t i = 0; i < source.atoms.size(); i += 37)
    CHECK((k.motion.apply(target.atoms[i].position) - source.atoms[i].position).norm() <= 1e-9);
  CHECK(k.motion.rotation.determinant() == Approx(1.0));
  // After the fit every atom is within rounding of its source atom, not on
  // it; snap_unmoved puts them there, and only them.
  Molecule fitted = moved(target, k.motion);
  fitted.atoms[5].position += Eigen::Vector3d(0, 0, 2 * kUnmovedWithin);  // a motion a file can state
  long off = 0;
  for (size_t i = 0; i < source.atoms.size(); ++i) off += fitted.atoms[i].position != source.atoms[i].position;
  CHECK(off > 0);
  CHECK(snap_unmoved(source, fitted) == static_cast<long>(source.atoms.size()) - 1);
  for (size_t i = 0; i < source.atoms.size(); ++i)
    CHECK((fitted.atoms[i].position == source.atoms[i].position) == (i != 5));

  // Two different molecules share no atom keys: the centroids are matched.
  const Molecule other = read_molecule(test::data_file("pept.pdb"));
  const Alignment c = align(source, other, AlignmentMethod::automatic);
  CHECK(c.used == AlignmentMethod::centroid);
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  for (const Atom& atom : source.atoms) a += atom.position;
  for (const Atom& atom : moved(other, c.motion).atoms) b += atom.position;
  CHECK((a / source.atoms.size() - b / other.atoms.size()).norm() <= 1e-9);
  CHECK_THROWS_AS(align(source, other, AlignmentMethod::kabsch), ContractError);
  CHECK(align(source, other, AlignmentMethod::none).motion.translation.norm() == 0.0);

  // Two proteins numbered alike (ubiquitin, HIV protease chain A): their
  // backbone atoms share chain, number and name, some residues even their
  // type, but they are not one molecule.
  const Molecule protease = read_molecule(test::data_file("1hpv.pdb"));
  const Alignment unrelated = align(source, protease, AlignmentMethod::automatic);
  CHECK(unrelated.used == AlignmentMethod::centroid);
  const Alignment forced = align(source, protease, AlignmentMethod::kabsch);
  CHECK(forced.used == AlignmentMethod::kabsch);
  CHECK(forced.matched < static_cast<long>(source.atoms.size()) / 2);

  // Two models of one NMR ensemble: every heavy atom matches, and the fit is
  // a real one (not zero: the models differ).
  const auto models = read_all_models(test::data_file("2k39_3models.pdb"));
  const Alignment nmr = align(models[0], models[1], AlignmentMethod::automatic);
  CHECK(nmr.used == AlignmentMethod::kabsch);
  CHECK(nmr.matched == static_cast<long>(models[0].atoms.size()));
  CHECK(nmr.rmsd > 0.01);
  CHECK(nmr.rmsd < 3.0);
}
