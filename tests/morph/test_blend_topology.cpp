// The blend's carried topology (morph/blend_topology.hpp) against
// skin_topology counted from scratch at every frame: every change of the
// skin's topology between two frames must lie in a window, and a count
// carried to a frame must be that frame's own.
#include "test_support.hpp"
#include "two_balls.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/morph/blend_topology.hpp"
#include "skinmesh/morph/events.hpp"

#include <catch2/catch.hpp>

using namespace skinmesh;

namespace {

std::vector<Ball> molecule_balls(const char* file, int model = 1) {
  return test::centred_model(test::data_file(file), model);
}

TopologyWindows windows_of(const std::vector<Ball>& source, const std::vector<Ball>& target) {
  const std::vector<BallPair> pairs = live_pairs(source, target);
  const SkinComplex middle = build_skin_complex(interpolated_balls(source, target, pairs, 0.5), {0.5});
  const MorphOracle oracle(source, target, 0.5);
  return TopologyWindows(middle, cell_sizes(middle, source, target, pairs), source, target, pairs, oracle);
}

struct Run {
  long changes = 0;      // frame to frame, by skin_topology from scratch
  long carried = 0;      // frames whose count was carried
  long blind_wrong = 0;  // frames a carrier without windows gets wrong
  long candidates = 0, decided = 0;  // the carrier's roots, and those it asked the oracle about
};

// Frames at t = k/(frames+1), k = 1..frames.
Run check_frames(const std::vector<Ball>& source, const std::vector<Ball>& target, int frames) {
  const std::vector<BallPair> pairs = live_pairs(source, target);
  TopologyWindows windows = windows_of(source, target);
  CarriedTopology carried(windows), blind{TopologyWindows{}};
  Run run;
  SkinTopology before;
  for (int k = 1; k <= frames; ++k) {
    const double t = k / (frames + 1.0), t_before = (k - 1) / (frames + 1.0);
    const std::vector<Ball> balls = interpolated_balls(source, target, pairs, t);
    const SkinTopology truth = skin_topology(balls);
    INFO("t = " << t << ": from scratch " << truth.text());
    const CountedTopology counted = carried.at(t, balls);
    CHECK(counted.topology == truth);
    CHECK(counted.counted_at <= t);
    run.blind_wrong += blind.at(t, balls).topology != truth;
    if (k > 1 && truth != before) {
      ++run.changes;
      CHECK(windows.meets(t_before, t));
    }
    before = truth;
  }
  run.carried = carried.carried();
  run.candidates = carried.windows().candidates();
  run.decided = carried.windows().decided();
  CHECK(carried.carried() + carried.counted() == frames);
  return run;
}

}  // namespace

TEST_CASE("blend topology: every change between frames lies in a window, and a carried count is the frame's own",
          "[morph][topology][large]") {
  SECTION("2k39 model 1 -> 3, 201 frames") {
    const Run run = check_frames(molecule_balls("2k39_3models.pdb", 1), molecule_balls("2k39_3models.pdb", 3), 201);
    CHECK(run.changes >= 5);        // premise: the topology does change between frames
    CHECK(run.blind_wrong > 0);     // and carrying without the windows would miss it
    CHECK(run.carried >= 201 / 2);  // most frames carry a count
  }
  SECTION("pept -> 3al1, 101 frames (many changes)") {
    const Run run = check_frames(molecule_balls("pept.pdb"), molecule_balls("3al1.pdb"), 101);
    CHECK(run.changes >= 20);
    CHECK(run.blind_wrong > 0);
    CHECK(run.carried > 0);
    CHECK(run.decided < run.candidates / 2);  // a step with a change stops at its first
  }
}

TEST_CASE("blend topology on degenerate overlays: unmoved atoms, two balls", "[morph][topology]") {
  SECTION("2k39 with a third of its atoms moved (unmoved atoms: a degenerate overlay), 101 frames") {
    const std::vector<Ball> m1 = molecule_balls("2k39_3models.pdb", 1);
    std::vector<Ball> part = m1;
    for (size_t i = 0; i < part.size(); i += 3) part[i].center += Eigen::Vector3d(0.6, -0.3, 0.2);
    const Run run = check_frames(m1, part, 101);
    CHECK(run.changes >= 2);
    CHECK(run.blind_wrong > 0);
    CHECK(run.carried >= 101 / 2);
  }
  SECTION("two balls that merge, and pinch off going back") {
    const test::TwoBallMorph two;
    for (bool forward : {true, false}) {
      const Run run = check_frames(forward ? two.source : two.target, forward ? two.target : two.source, 41);
      CHECK(run.changes == 1);
      CHECK(run.blind_wrong > 0);
      CHECK(run.carried >= 35);
    }
  }
}

TEST_CASE("blend topology: windows meet an interval they overlap, in either order, and no other", "[morph][topology]") {
  TopologyWindows w({{0.5, 0.5}, {0.2, 0.3}});
  CHECK(w.meets(0.1, 0.2));
  CHECK(w.meets(0.25, 0.26));
  CHECK(w.meets(0.6, 0.4));
  CHECK(w.meets(0.5, 0.5));
  CHECK_FALSE(w.meets(0.31, 0.49));
  CHECK_FALSE(w.meets(0.0, 0.19));
  CHECK_FALSE(w.meets(0.51, 1.0));
  CarriedTopology carried(w);
  const std::vector<Ball> one{{Eigen::Vector3d::Zero(), 2.0}};
  CHECK(carried.at(0.35, one).counted_at == 0.35);
  CHECK(carried.at(0.45, one).counted_at == 0.35);  // no window between
  CHECK(carried.at(0.55, one).counted_at == 0.55);  // the window at 0.5 between
  CHECK(carried.at(1.0, one).counted_at == 1.0);    // the ends are counted: the overlay is not theirs
}
