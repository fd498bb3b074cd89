#pragma once
// The figures of a laboratory run: figure.png (the final state: material coloured by speed; in 3D
// the plan view of the flow depth) and comparison.png (the section with the monitors beside the
// scenario's reference values, or in 3D the plan view with the depth map and the obstacles' shadows).
#include <string>

#include "engine/vof/backend.hpp"
#include "jobs/drivers/vof_lab/monitors.hpp"
#include "jobs/drivers/vof_lab/results.hpp"
#include "jobs/drivers/vof_lab/setup.hpp"
#include "jobs/figures/lab_figure.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_lab {

/// figure.png; `vmax`: the speed at the top of the colour scale [m/s].
void write_state_figure(const std::string& path, const engine::vof::VofBackend& s, const LabGrid& g, double vmax);

/// comparison.png's title: the scenario's name, the time and the cell size (a scenario's name may
/// describe its file's resolution while the run took another).
std::string figure_title(const ResolvedScenario& r, const LabGrid& g, double t);

/// comparison.png of a plane set-up.
void write_section_comparison(const std::string& path, const std::string& title, const v1::Lab& L, const LabSetup& su,
                              const engine::vof::VofBackend& s, const Deposit& dep, const LabMonitors& mon);

}  // namespace runout::jobs::vof_lab
