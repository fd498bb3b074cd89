#pragma once
// The run driver of the VOF engine for the laboratory set-ups (scenario engine "vof", block `lab`):
// mesh and conditions from the scenario, the run with progress and cancellation, and the outputs:
// fields.h5 + fields.xmf (alpha, velocity, pressure, granular viscosity at the write interval, for
// ParaView), figure.png (the final state: material coloured by speed) and run.json with the
// figures the validation cases compare (peak speed and its time, time to rest, front position,
// upper surface angle, volume error, alpha bounds, divergence, cost per cell and step).
#include <string>

#include "jobs/drivers/run.hpp"

namespace runout::jobs {

/// Called by run_scenario for a resolved "vof" scenario.
RunSummary run_lab(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);

}  // namespace runout::jobs
