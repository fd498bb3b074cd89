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

/// Progress as reported to the caller every `progress_every` steps.
struct Progress {
  double t = 0, dt = 0, mass = 0, max_speed = 0, kinetic_energy = 0, active_fraction = 0;
  long step = 0;
  const char* dt_limit = "";  ///< what set dt (the VOF engine: engine::vof::StepStats::dt_limit)
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
