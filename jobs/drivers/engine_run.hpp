#pragma once
// The engines as the run driver (jobs/drivers/run.cpp) sees them: a registry row per engine set-up,
// whose `prepare` builds the run (terrain or laboratory geometry, mesh, initial or restored state)
// and returns it as an EngineRun: the engine the one loop steps (engine/stepping.hpp), the loop's
// schedule, the hooks that keep hazard maps, monitors, frames and checkpoints, and the results at
// the end. A new engine or set-up is one file with its EngineRun, its prepare_* below and one row in
// engines.cpp; the scenario's resolution names the row (ResolvedScenario::engine).
#include <memory>
#include <string>
#include <string_view>

#include "engine/stepping.hpp"
#include "jobs/drivers/run.hpp"

namespace runout::jobs {

/// What the driver measured of the run [s].
struct RunTimes {
  double prepare = 0, run = 0;
  double cpu = 0;  ///< processor time of the loop (all threads)
};

class EngineRun {
 public:
  virtual ~EngineRun() = default;
  virtual engine::SteppingEngine& engine() = 0;
  /// The end time, stop rule, step limit and the intervals of frames and checkpoints (the driver sets
  /// the progress cadence).
  virtual engine::LoopSchedule schedule() const = 0;
  /// After each step, the frames and the checkpoints (the driver adds the progress report, and drops
  /// the checkpoint hook when the run writes none).
  virtual engine::LoopHooks hooks() = 0;
  /// The results (outputs, run.json) of a run that stopped for `stop`; a cancelled run writes none
  /// unless its engine says otherwise.
  virtual RunSummary finish(engine::StopReason stop, const RunTimes& times) = 0;

  /// The loop's running figures: restored from the checkpoint of a continued run.
  engine::LoopState loop;
  bool continued = false;
};

struct EngineRow {
  std::string_view name;     ///< ResolvedScenario::engine
  std::string_view caption;  ///< the engine as the maps and summaries name it
  std::unique_ptr<EngineRun> (*prepare)(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);
};

/// The row of ResolvedScenario::engine; throws ScenarioError naming the rows when there is none.
const EngineRow& engine_row(std::string_view name);

// The set-ups (one file each): the depth-averaged engine on the DEM (depth_averaged.cpp), the 3D
// engine's laboratory set-ups (vof_lab/run.cpp) and the 3D engine on the DEM (vof_terrain/run.cpp).
std::unique_ptr<EngineRun> prepare_depth_averaged(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);
std::unique_ptr<EngineRun> prepare_vof_lab(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);
std::unique_ptr<EngineRun> prepare_vof_terrain(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);

}  // namespace runout::jobs
