#pragma once
// The 3D engine as the run loop (engine/stepping.hpp) drives it: one back-end step per loop step,
// reported in the loop's figures; the VOF step's own statistics stay at hand for the set-ups' hooks.
#include "engine/stepping.hpp"
#include "engine/vof/backend.hpp"

namespace runout::engine::vof {

class VofStepping final : public SteppingEngine {
 public:
  /// `steps_before`: the steps of the run before the checkpoint it was restored from (the progress
  /// cadence counts on from there). The solver must outlive this.
  explicit VofStepping(VofBackend& solver, long steps_before = 0) : s_(solver), steps_(steps_before) {}
  double time() const override { return s_.time(); }
  long steps() const override { return steps_; }
  StepReport step(double t_end) override;
  /// Sum over the cells of alpha V |U|^2 / 2.
  double kinetic_energy() const override;
  bool any(bool v) const override { return s_.any(v); }
  /// The last step's statistics (Courant numbers, solver iterations, timings).
  const StepStats& last() const { return last_; }

 private:
  VofBackend& s_;
  long steps_;
  StepStats last_;
};

}  // namespace runout::engine::vof
