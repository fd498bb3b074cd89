#pragma once
// The run driver of the VOF engine for the laboratory set-ups (scenario engine "vof", block `lab`):
// mesh and conditions from the scenario (setup.hpp, config.hpp), the run with progress, monitors
// (monitors.hpp), checkpoints and cancellation, and the outputs: fields.h5 + fields.xmf
// (jobs/formats/lab_frames.hpp), figure.png and comparison.png (figures.hpp) and run.json
// (jobs/formats/run_record.hpp) with the figures the validation cases compare (results.hpp).
#include <string>

#include "jobs/drivers/run.hpp"

namespace runout::jobs {

/// Called by run_scenario for a resolved "vof" scenario.
RunSummary run_lab(const ResolvedScenario& s, const std::string& out_dir, const RunOptions& opt);

}  // namespace runout::jobs
