#pragma once
// The seam between an engine and the time loop (as OpenFOAM's foamRun separates a solver module from
// its time loop): an engine advances by one step of its own bound and reports what the step did; the
// one loop, run_steps, owns everything around the steps for every engine: the end time, the
// kinetic-energy stop rule, the step limit, the cadence of frames and checkpoints, progress and
// cancellation. What a frame or a checkpoint holds is the caller's (the job drivers', a test's), handed
// in as hooks. docs/design/architecture.md, "One run loop".
#include <functional>
#include <limits>

#include "engine/run_control.hpp"

namespace runout::engine {

/// An engine as the loop sees it. Implementations: engine::Sh2dEngine (depth-averaged),
/// engine::vof::VofStepping (3D); tests drive toy engines through the same loop.
class SteppingEngine {
 public:
  virtual ~SteppingEngine() = default;
  virtual double time() const = 0;
  virtual long steps() const = 0;
  /// One step of the engine's own time-step bound (CFL or Courant numbers), never past t_end.
  virtual StepReport step(double t_end) = 0;
  /// The material's kinetic energy now, in StepReport::kinetic_energy's units.
  virtual double kinetic_energy() const = 0;
  /// Whether v holds on any of the processes that step this engine together (an engine split over
  /// MPI ranks): a stop that one process decides (a cancel) stops them all at the same step.
  virtual bool any(bool v) const { return v; }
};

/// When a run stops and when frames and checkpoints fall due.
struct LoopSchedule {
  double t_end = 0;
  /// Stop when the kinetic energy falls below this fraction of its peak so far (0: never).
  double stop_fraction = 0;
  long max_steps = std::numeric_limits<long>::max();
  double frame_interval = 0;       ///< [s]; 0: no frames
  bool final_frame = false;        ///< also a frame of the state the run ends with (unless just written)
  double checkpoint_interval = 0;  ///< [s]; 0: checkpoints only when the run is cancelled
  long progress_every = 50;        ///< steps between two progress reports
};

/// The loop's running figures: what a checkpoint must carry besides the engine's state so that a
/// continued run stops, writes frames and reports as the uninterrupted one.
struct LoopState {
  double kinetic_energy_peak = 0;
  /// The time of the next regular frame; a continued run whose checkpoint does not carry it (not
  /// after the checkpoint's time) takes the first multiple of the interval after that time.
  double next_frame = 0;
  double last_frame = -1;  ///< the time of the last frame written (-1: none)
};

/// What the caller does around the steps. Every hook is optional.
struct LoopHooks {
  std::function<void(const StepReport&)> after_step;  ///< hazard maps, monitors, running figures
  std::function<void(double t)> frame;                ///< write a frame of the engine's state at t
  /// Write a checkpoint of the engine's state and of the loop's (valid during the call only).
  std::function<void(const LoopState&)> checkpoint;
  ProgressHook progress;  ///< false: cancel (ignored on the step that reaches the end time)
};

/// The frames' and checkpoints' times are met within this [s] (sums of steps do not hit them exactly).
inline constexpr double kTimeTolerance = 1e-12;

/// Steps `engine` from its time to the schedule's end or until a stop rule or the progress hook
/// stops it. `continued`: the engine and `state` were restored from a checkpoint (no frame at the
/// start; the stop rule looks at the restored state first, since a cancelled run's checkpoint is
/// taken before the rule saw its last step). Returns why the loop stopped.
StopReason run_steps(SteppingEngine& engine, const LoopSchedule& schedule, LoopState& state, const LoopHooks& hooks,
                     bool continued);

}  // namespace runout::engine
