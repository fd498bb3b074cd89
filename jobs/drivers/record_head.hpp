#pragma once
// The part of the run record every engine writes alike: the software, the engine, when, the scenario
// and its input files' digests, and how the run was executed (threads, PETSC_OPTIONS).
#include <string>

#include "jobs/formats/run_record.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs {

v1::RunRecord run_record_head(const ResolvedScenario& s, const std::string& engine);

}  // namespace runout::jobs
