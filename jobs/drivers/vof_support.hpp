#pragma once
// What the VOF engine's set-ups (laboratory and terrain) share: PETSc's turn and its options.
#include <mutex>
#include <string>

#include "engine/vof/backend.hpp"
#include "jobs/drivers/run.hpp"

namespace runout::jobs {

/// PETSc keeps process-wide state and is not thread-safe: in a server with several workers, VOF
/// runs take turns by holding this (depth-averaged runs are not affected).
std::mutex& petsc_turn();

/// PETSc's options database as the run used it (PETSC_OPTIONS and the engine's defaults); empty
/// before PETSc started.
std::string petsc_options();

}  // namespace runout::jobs
