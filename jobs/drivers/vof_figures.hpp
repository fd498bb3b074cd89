#pragma once
// The running figures of a 3D run, updated after every step by both VOF set-ups (laboratory and
// terrain): peak speed, time to rest, alpha bounds, divergence, the active region, solver cost. They
// travel with a checkpoint, so that a continued run's record is the uninterrupted run's.
#include <string>

#include "engine/vof/backend.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "runout/v1/run_record.pb.h"

namespace runout::jobs {

/// The figures every step updates.
struct RunningFigures {
  double peak = 0, t_peak = 0, t_rest = -1, pressure_s = 0, pressure_solve_s = 0, alpha_min = 1, alpha_max = 0, div = 0, last_speed = 0;
  long steps = 0, p_its = 0;
  double active_sum = 0;
  int active_max = 0;

  void step(const engine::vof::StepStats& st);
  void save(VofCheckpoint& cp) const;
  /// Throws ScenarioError naming `path` when the checkpoint lacks a figure.
  void restore(const VofCheckpoint& cp, const std::string& path);
  /// solver.*, results' speeds and times, the pressure timings.
  void write(v1::RunRecord& rec) const;
};

}  // namespace runout::jobs
