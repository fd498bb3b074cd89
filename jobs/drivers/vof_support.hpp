#pragma once
// What the VOF engine's run drivers (laboratory and terrain) share: PETSc's turn and its options,
// the schedule of frames and checkpoints, and the progress report after a step.
#include <mutex>
#include <string>

#include "engine/vof/solver.hpp"
#include "jobs/drivers/run.hpp"

namespace runout::jobs {

/// PETSc keeps process-wide state and is not thread-safe: in a server with several workers, VOF
/// runs take turns by holding this (depth-averaged runs are not affected).
std::mutex& petsc_turn();

/// PETSc's options database as the run used it (PETSC_OPTIONS and the engine's defaults); empty
/// before PETSc started.
std::string petsc_options();

/// The first multiple of `interval` after time t (frames and checkpoints after a restart).
double next_multiple(double interval, double t);

/// Every opt.progress_every steps, the step to opt.progress (material volume, fastest material,
/// the active region's share of `cells`); false when the hook asks the run to stop.
bool report_step(const RunOptions& opt, const engine::vof::StepStats& st, long steps, int cells);

}  // namespace runout::jobs
