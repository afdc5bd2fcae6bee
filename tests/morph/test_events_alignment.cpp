// Topology events ahead of time (eq. 18: every cell's size is quadratic in t)
// and the alignment of a target onto its source.
#include "test_support.hpp"
#include "blend_events.hpp"
#include "two_balls.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/events.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

using namespace skinmesh;

TEST_CASE("every overlay cell's size is the quadratic fitted at three frames", "[morph][events]") {
  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m2 = test::centred_model(test::data_file("2k39_3models.pdb"), 2);
  const test::BlendEvents blend(m1, m2);
  const auto& live = blend.live;
  const SkinComplex& middle = blend.middle;
  const std::vector<CellSize>& sizes = blend.sizes;
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

TEST_CASE("cancelling events: a void sealed and filled in one step pairs, nothing else does", "[morph][events]") {
  // Cells 0 and 1 at one place, cell 2 two A away.
  std::vector<CellSize> sizes(3);
  sizes[1].center_half = Eigen::Vector3d(0.1, 0, 0);
  sizes[2].center_half = Eigen::Vector3d(2, 0, 0);
  const auto event = [](double t, int cell, int dim, int euler) {
    TopologyEvent e;
    e.t = t;
    e.cell = cell;
    e.dim = dim;
    e.euler_change = euler;
    return e;
  };
  const auto partners = [&](const std::vector<TopologyEvent>& events, std::vector<char> skip = {}) {
    if (skip.empty()) skip.assign(events.size(), 0);
    return cancelling_partners(events, sizes, 0.3, 0.4, skip);
  };
  const TopologyEvent sealed = event(0.32, 0, 2, +2), filled = event(0.35, 1, 3, -2);
  CHECK(partners({sealed, filled}) == std::vector<int>{1, 0});
  CHECK(partners({event(0.32, 0, 1, +2), event(0.35, 1, 0, -2)}) == std::vector<int>{1, 0});  // a piece pinched off, gone
  CHECK(partners({event(0.36, 0, 2, +2), filled}) == std::vector<int>{-1, -1});  // filled before sealed: another void
  CHECK(partners({sealed, event(0.35, 2, 3, -2)}) == std::vector<int>{-1, -1});  // two A apart
  CHECK(partners({event(0.25, 0, 2, +2), filled}) == std::vector<int>{-1, -1});  // sealed in the step before
  CHECK(partners({event(0.32, 0, 1, +2), filled}) == std::vector<int>{-1, -1});  // a neck, not a seal
  CHECK(partners({sealed, filled}, {0, 1}) == std::vector<int>{-1, -1});        // the filling accounted for
  // Two seals and one filling: the filling takes the nearer seal, once.
  std::vector<TopologyEvent> three{event(0.31, 2, 2, +2), sealed, filled};
  sizes[2].center_half = Eigen::Vector3d(0.3, 0, 0);
  CHECK(partners(three) == std::vector<int>{-1, 2, 1});
  CHECK_THROWS_AS(cancelling_partners(three, sizes, 0.3, 0.4, {0}), ContractError);
}

TEST_CASE("cancelling events of pept -> 3al1 are voids the alpha complex sees only inside the step",
          "[morph][events][large]") {
  // Independent of the events' bookkeeping: the skin's topology counted
  // from B(t)'s alpha complex (skin_topology) before, between and after
  // every pair that no other event interleaves.
  const std::vector<Ball> source = test::centred_model(test::data_file("pept.pdb"), 1);
  const std::vector<Ball> target = test::centred_model(test::data_file("3al1.pdb"), 1);
  test::BlendEvents blend(source, target);
  const std::vector<TopologyEvent>& events = blend.with_critical(source, target).critical;
  const std::vector<CellSize>& sizes = blend.sizes;
  const auto& live = blend.live;
  const auto topology_at = [&](double t) { return skin_topology(interpolated_balls(source, target, live, t)); };
  long pairs = 0, isolated = 0;
  for (int k = 0; k < 100; ++k) {
    const double from = k / 100.0, to = (k + 1) / 100.0;
    const std::vector<int> partner = cancelling_partners(events, sizes, from, to, std::vector<char>(events.size(), 0));
    for (size_t i = 0; i < events.size(); ++i) {
      if (partner[i] < 0 || events[i].euler_change > 0) continue;  // each pair once, by its vanishing event
      ++pairs;
      const TopologyEvent& made = events[static_cast<size_t>(partner[i])];
      const TopologyEvent& gone = events[i];
      const double margin = 1e-6;
      const bool alone = std::none_of(events.begin(), events.end(), [&](const TopologyEvent& e) {
        return &e != &made && &e != &gone && e.t > made.t - margin && e.t < gone.t + margin;
      });
      if (!alone || gone.t - made.t < 4 * margin) continue;
      ++isolated;
      const SkinTopology before = topology_at(made.t - margin), inside = topology_at((made.t + gone.t) / 2),
                         after = topology_at(gone.t + margin);
      INFO("pair at t = " << made.t << " .. " << gone.t << ", dimensions " << made.dim << ", " << gone.dim);
      CHECK(before == after);
      CHECK(inside.components == before.components + 1);
      CHECK(inside.voids == before.voids + (gone.dim == 3 ? 1 : 0));
    }
  }
  INFO(pairs << " cancelling pairs in 100 steps, " << isolated << " with no other event between them");
  CHECK(isolated >= 3);  // premise: the morph has such voids
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
