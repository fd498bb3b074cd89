#pragma once
// The figures of a laboratory run's final state, written into the run record: the deposit (front,
// height, surface angles, volumes), the velocity stations, and in 3D the flow depth map with the
// obstacles' shadows and, on the curved chute, where the deposit lies. Pure functions of the set-up
// and the solver's final state.
#include <vector>

#include "engine/vof/backend.hpp"
#include "jobs/drivers/vof_lab/setup.hpp"
#include "jobs/figures/lab_figure.hpp"
#include "runout/v1/run_record.pb.h"

namespace runout::jobs::vof_lab {

/// mesh: the cells and the grid's size and spacing.
void write_mesh(const LabSetup& su, v1::RunRecord& rec);

/// The deposit from the column heights (in 3D averaged across the width).
struct Deposit {
  std::vector<double> h;  ///< column height per i [m]
  double volume = 0;      ///< the material's volume at the end [m^3]
  double front = 0, height = 0;
  int imax = 0;           ///< the right end of the highest plateau
  double upper_angle = 0, mean_angle = 0;  ///< [deg]
};
Deposit deposit(const LabSetup& su, const engine::vof::VofBackend& s);

/// results.front_x_m ... volume figures and frames.
void write_deposit(const Deposit& d, const LabSetup& su, int frames, v1::RunRecord& rec);

/// The stations of lab.stations_x (centre line in 3D): depth, depth-averaged, surface and basal
/// velocity along x, the basal speed, the strain rate du/dy and the profile.
void write_stations(const v1::Lab& L, const LabSetup& su, const engine::vof::VofBackend& s, v1::RunRecord& rec);

/// 3D set-ups (validation.md B7, B8): the record's chute (and curved_chute) and the plan figure's
/// depth and velocity map.
void write_chute(const v1::Lab& L, const LabSetup& su, const engine::vof::VofBackend& s, figures::PlanFigure& plan, v1::RunRecord& rec);

}  // namespace runout::jobs::vof_lab
