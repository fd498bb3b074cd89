#pragma once
// Shared run-control types of the engines: why a run stopped, and the cooperative progress /
// cancellation hook through which the caller (the job driver, the CLI) follows a run. Numerics never
// print: they call the hook, and the caller decides what to show.
#include <functional>
#include <limits>
#include <string_view>

namespace runout::engine {

enum class StopReason { end_time, kinetic_energy, cancelled, max_steps };
inline std::string_view to_string(StopReason r) {
  switch (r) {
    case StopReason::end_time: return "end-time";
    case StopReason::kinetic_energy: return "kinetic-energy";
    case StopReason::cancelled: return "cancelled";
    case StopReason::max_steps: return "max-steps";
  }
  return "?";
}

/// What one step did, in the figures the run loop (engine/stepping.hpp) and the progress report need.
struct StepReport {
  double t = 0, dt = 0;        ///< the time reached, the step's length [s]
  const char* dt_limit = "";   ///< what bounded the step (an engine's own words; "" when it does not say)
  double mass = 0;             ///< volume of material [m^3]
  double kinetic_energy = 0;   ///< of the material, per unit density [m^5/s^2] (the stop rule's figure)
  double max_speed = 0;        ///< fastest flowing material [m/s]
  double active_fraction = 0;  ///< the share of the cells the step computed
};

/// Progress as reported to the caller every `progress_every` steps: the last step's report and the
/// steps so far.
struct Progress : StepReport {
  long step = 0;
};
/// Returns false to cancel the run (it then stops cleanly at the end of the step).
using ProgressHook = std::function<bool(const Progress&)>;

/// Time-loop controls common to both depth-averaged solvers.
struct TimeControl {
  double t_end = 10.0;          ///< end time [s]
  double cfl = 0.45;            ///< Courant number (stable up to 0.5)
  double dt_max = std::numeric_limits<double>::infinity();
  /// Stop when the kinetic energy has fallen below this fraction of its peak (0: never).
  double stop_fraction = 0.0;
  long max_steps = std::numeric_limits<long>::max();
  long progress_every = 50;
  ProgressHook progress;  ///< optional
};

}  // namespace runout::engine
