// The one time loop of every engine (engine/stepping.hpp).
#include "engine/stepping.hpp"

#include <algorithm>
#include <cmath>

namespace runout::engine {

namespace {

// The first multiple of `interval` after time t.
double next_multiple(double interval, double t) { return interval * (std::floor(t / interval + 1e-9) + 1); }

// The frames' schedule: a frame at t, and the next regular one after it.
struct Frames {
  const LoopSchedule& s;
  const LoopHooks& h;
  LoopState& st;
  bool on() const { return h.frame && s.frame_interval > 0; }
  void write(double t) {
    h.frame(t);
    st.last_frame = t;
    while (st.next_frame <= t + kTimeTolerance) st.next_frame += s.frame_interval;
  }
};

Progress progress_of(const StepReport& r, long steps) {
  Progress p;
  static_cast<StepReport&>(p) = r;
  p.step = steps;
  return p;
}

}  // namespace

StopReason run_steps(SteppingEngine& e, const LoopSchedule& s, LoopState& st, const LoopHooks& h, bool continued) {
  Frames frames{s, h, st};
  // Checkpoints fall at step boundaries only, the first at or after each multiple of the interval:
  // steps are never shortened for them, so they change nothing.
  const double cp_every = h.checkpoint && s.checkpoint_interval > 0 ? s.checkpoint_interval : 0.0;
  double next_cp = cp_every > 0 ? next_multiple(cp_every, e.time()) : HUGE_VAL;
  const auto settled = [&](double ke) {
    return s.stop_fraction > 0 && st.kinetic_energy_peak > 0 && ke < s.stop_fraction * st.kinetic_energy_peak;
  };
  const long every = std::max(1L, s.progress_every);
  StopReason stop = StopReason::end_time;
  bool go = true;
  if (!continued) {
    if (frames.on()) frames.write(e.time());
  } else if (frames.on() && st.next_frame <= e.time()) {
    st.next_frame = next_multiple(s.frame_interval, e.time());
  }
  if (continued && settled(e.kinetic_energy())) {
    stop = StopReason::kinetic_energy;
    go = false;
  }
  while (go && e.time() < s.t_end - kTimeTolerance) {
    if (e.steps() >= s.max_steps) {
      stop = StopReason::max_steps;
      break;
    }
    const StepReport r = e.step(s.t_end);
    if (h.after_step) h.after_step(r);
    if (frames.on() && r.t >= st.next_frame - kTimeTolerance) frames.write(r.t);
    st.kinetic_energy_peak = std::max(st.kinetic_energy_peak, r.kinetic_energy);
    // A cancel on the step that reaches the end time comes too late to matter; on the step the stop
    // rule ends the run it still stops the run with a checkpoint (continued, the rule ends it at once).
    const bool at_end = r.t >= s.t_end - kTimeTolerance;
    const bool cancel = h.progress && e.steps() % every == 0 && !h.progress(progress_of(r, e.steps()));
    if (e.any(cancel) && !at_end) {
      stop = StopReason::cancelled;
      if (h.checkpoint) h.checkpoint(st);  // the run can continue from here
      break;
    }
    if (settled(r.kinetic_energy)) {
      stop = StopReason::kinetic_energy;
      break;
    }
    if (cp_every > 0 && r.t >= next_cp - kTimeTolerance && !at_end) {
      h.checkpoint(st);
      while (next_cp <= r.t + kTimeTolerance) next_cp += cp_every;
    }
  }
  if (frames.on() && s.final_frame && st.last_frame != e.time()) frames.write(e.time());
  return stop;
}

}  // namespace runout::engine
