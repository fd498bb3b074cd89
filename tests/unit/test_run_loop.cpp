// The one run loop (engine/stepping.hpp) driving a toy engine: frames, checkpoints, cancellation,
// the stop rules and a continuation that gives the uninterrupted run's frames and stop.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "engine/stepping.hpp"

namespace {

using namespace runout::engine;

// A toy engine: a block whose speed falls by 10 % a step, with steps of at most 0.1 s.
class Toy final : public SteppingEngine {
 public:
  double t = 0, v = 1;
  long n = 0;
  double time() const override { return t; }
  long steps() const override { return n; }
  StepReport step(double t_end) override {
    StepReport r;
    r.dt = std::min(0.1, t_end - t);
    t += r.dt;
    v *= 0.9;
    ++n;
    r.t = t;
    r.mass = 1;
    r.max_speed = v;
    r.kinetic_energy = kinetic_energy();
    r.dt_limit = "toy";
    return r;
  }
  double kinetic_energy() const override { return 0.5 * v * v; }
};

// What a run of the toy did: its frames, checkpoints (with the toy's and the loop's state) and stop.
struct Record {
  std::vector<double> frames;
  struct Saved {
    Toy toy;
    LoopState loop;
  };
  std::vector<Saved> checkpoints;
  StopReason stop = StopReason::end_time;
};

Record drive(Toy& toy, const LoopSchedule& s, LoopState& st, bool continued, long cancel_at_step = -1) {
  Record rec;
  LoopHooks h;
  h.frame = [&](double t) { rec.frames.push_back(t); };
  h.checkpoint = [&](const LoopState& loop) { rec.checkpoints.push_back({toy, loop}); };
  h.progress = [&](const Progress& p) { return p.step != cancel_at_step; };
  rec.stop = run_steps(toy, s, st, h, continued);
  return rec;
}

LoopSchedule schedule() {
  LoopSchedule s;
  s.t_end = 1.0;
  s.frame_interval = 0.25;
  s.final_frame = true;
  s.checkpoint_interval = 0.35;
  s.progress_every = 1;
  return s;
}

TEST(RunLoop, FramesAtTheStartEachIntervalAndTheEnd) {
  Toy toy;
  LoopState st;
  auto s = schedule();
  s.frame_interval = 0.3;
  const auto rec = drive(toy, s, st, false);
  EXPECT_EQ(rec.stop, StopReason::end_time);
  EXPECT_NEAR(toy.t, 1.0, 1e-12);
  EXPECT_EQ(toy.n, 10);
  // t = 0, the first steps at or after 0.3, 0.6, 0.9, and the final state.
  const std::vector<double> want{0, 0.3, 0.6, 0.9, 1.0};
  ASSERT_EQ(rec.frames.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) EXPECT_NEAR(rec.frames[k], want[k], 1e-9);
  s.final_frame = false;
  Toy again;
  LoopState st2;
  EXPECT_EQ(drive(again, s, st2, false).frames.size(), 4u);
}

TEST(RunLoop, CheckpointsAtTheFirstStepAfterEachMultipleButNotAtTheEnd) {
  Toy toy;
  LoopState st;
  const auto rec = drive(toy, schedule(), st, false);
  ASSERT_EQ(rec.checkpoints.size(), 2u);  // at 0.4 (after 0.35) and 0.7; 1.05 lies past the end
  EXPECT_NEAR(rec.checkpoints[0].toy.t, 0.4, 1e-9);
  EXPECT_NEAR(rec.checkpoints[1].toy.t, 0.7, 1e-9);
  EXPECT_NEAR(rec.checkpoints[1].loop.kinetic_energy_peak, 0.5 * 0.81, 1e-15);  // the first step's
}

TEST(RunLoop, CancelStopsWithACheckpointUnlessTheEndTimeIsReached) {
  Toy toy;
  LoopState st;
  auto rec = drive(toy, schedule(), st, false, 5);
  EXPECT_EQ(rec.stop, StopReason::cancelled);
  EXPECT_EQ(toy.n, 5);
  ASSERT_EQ(rec.checkpoints.size(), 2u);  // the regular one at 0.4, the cancelled run's at 0.5
  EXPECT_NEAR(rec.checkpoints.back().toy.t, 0.5, 1e-9);
  EXPECT_NEAR(rec.frames.back(), 0.5, 1e-9);  // the state it stopped with
  // Cancelled on the step that reaches the end time: the run is complete.
  Toy last;
  LoopState st2;
  rec = drive(last, schedule(), st2, false, 10);
  EXPECT_EQ(rec.stop, StopReason::end_time);
}

TEST(RunLoop, KineticEnergyRuleAndStepLimit) {
  auto s = schedule();
  s.t_end = 100;
  s.stop_fraction = 0.01;  // 0.9^(2n) < 0.01 * 0.81: n = 23
  Toy toy;
  LoopState st;
  EXPECT_EQ(drive(toy, s, st, false).stop, StopReason::kinetic_energy);
  EXPECT_EQ(toy.n, 23);
  s.max_steps = 7;
  Toy capped;
  LoopState st2;
  EXPECT_EQ(drive(capped, s, st2, false).stop, StopReason::max_steps);
  EXPECT_EQ(capped.n, 7);
}

// A run cancelled at any step and continued from its checkpoint writes the uninterrupted run's
// frames (none twice) and stops where it stops.
TEST(RunLoop, ContinuedRunMatchesTheUninterruptedOne) {
  auto s = schedule();
  s.t_end = 100;
  s.stop_fraction = 0.01;
  Toy whole;
  LoopState st;
  const auto all = drive(whole, s, st, false);
  for (long k = 1; k <= whole.n; ++k) {  // also at the step the stop rule ends the run
    Toy first;
    LoopState st1;
    const auto head = drive(first, s, st1, false, k);
    ASSERT_EQ(head.stop, StopReason::cancelled);
    Toy resumed = head.checkpoints.back().toy;
    LoopState st2 = head.checkpoints.back().loop;
    const double t_cp = resumed.t;
    const auto tail = drive(resumed, s, st2, true);
    std::vector<double> later;  // the uninterrupted run's frames after the checkpoint
    for (double f : all.frames)
      if (f > t_cp) later.push_back(f);
    EXPECT_EQ(tail.frames, later) << k;
    EXPECT_EQ(tail.stop, all.stop) << k;
    EXPECT_EQ(resumed.n, whole.n) << k;
    EXPECT_EQ(resumed.v, whole.v) << k;
  }
  // A checkpoint taken before the stop rule saw its step: the continued run stops at once.
  Toy rest;
  rest.v = 1e-3;
  LoopState peak;
  peak.kinetic_energy_peak = 0.5;
  EXPECT_EQ(drive(rest, s, peak, true).stop, StopReason::kinetic_energy);
  EXPECT_EQ(rest.n, 0);
}

}  // namespace
