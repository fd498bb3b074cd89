#pragma once
// The nest's boundary patch ("nest", vof_terrain/setup.cpp splits it from the sides) as the 3D engine
// takes it: the coupled inflow (engine/vof/bc/nest_inflow.cpp) fed from the depth-averaged run's
// record (boundary.hpp). Each face of the patch belongs to the grid face between its column's grid
// cell and the cell outside; over a 3D step the mean flux q that the record gives for that grid face
// enters below the outside cell's vertical depth H (capped at the band's height), as a plug: the
// normal speed q / (H dx) (so that the volume the faces take in is the record's, dx the grid's cell),
// the depth-averaged velocity's part along the face, each face filled by the share of its layer below
// H.
#include <vector>

#include "engine/vof/config.hpp"
#include "jobs/drivers/nest/boundary.hpp"
#include "jobs/drivers/vof_terrain/setup.hpp"

namespace runout::jobs::nest {

/// The condition of the patch "nest" of `su`'s mesh, reading `b` (both outlive the run). Throws
/// ScenarioError when a face of the patch matches no grid face of the record.
engine::vof::PatchBc nest_inflow(const vof_terrain::TerrainSetup& su, const NestBoundary& b);

/// The largest time step that keeps the inflow's Courant number within `co` on the nest's columns:
/// co times the column's width over the fastest speed recorded at the boundary (at least 1 m/s).
double nest_max_step(const vof_terrain::TerrainSetup& su, const NestBoundary& b, double co);

}  // namespace runout::jobs::nest
