#pragma once
// The 3D nest of a depth-averaged run (scenario `nest`; one-way coupling): after the depth-averaged
// run, which recorded the flux through the nest's boundary (boundary.hpp), the 3D engine runs the
// nest (ResolvedScenario::nest: the scenario on the DEM, its corridor the nest) into OUT/nest with
// that inflow, to the scenario's end time or its own stop rule (after the depth-averaged run's end
// nothing enters); its maps then replace the depth-averaged maps inside the nest's cells.
#include <string>

#include "engine/sh2d.hpp"
#include "jobs/drivers/nest/boundary.hpp"
#include "jobs/drivers/run.hpp"

namespace runout::jobs::nest {

/// Runs the nest of `parent` (parent.nest set) into `dir` with the record `b`, and writes its maps
/// into `hz` inside the nest's cells. The nest's layers, when the scenario gives none: a fifth and
/// eight times the deepest flow the depth-averaged run had through the nest (its boundary and cells).
/// A nest without release starts 1 s before material first enters it (`release_inside`: at 0).
NestSummary run_nest(const ResolvedScenario& parent, const NestBoundary& b, engine::HazardMaps& hz, const std::string& dir,
                     const RunOptions& opt, bool release_inside);

}  // namespace runout::jobs::nest
