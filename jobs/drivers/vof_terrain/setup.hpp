#pragma once
// The set-up of a 3D run on the DEM: the scenario's grid and release (as the depth-averaged engine
// prepares them), the corridor (corridor.hpp), the terrain-following mesh over the corridor's
// columns inside the domain, the release's phase
// fraction on it, and the named points placed on the grid.
#include <string>
#include <vector>

#include "engine/vof/mesh_quality.hpp"
#include "jobs/drivers/hazard_maps.hpp"
#include "jobs/drivers/vof_terrain/corridor.hpp"
#include "jobs/drivers/vof_terrain/hazard.hpp"
#include "jobs/drivers/vof_terrain/mesh.hpp"
#include "jobs/scenario/scenario.hpp"
#include "terrain/column_mesh.hpp"
#include "terrain/points.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs::vof_terrain {

struct NamedPoint {
  std::string name;
  terrain::GridPoint at;
  std::size_t column = 0;       ///< its grid cell, j * nx + i
  std::size_t mesh_column = 0;  ///< the mesh's column it lies in (Columns numbering)
};

/// The rule of mesh.refinement 0: the smallest of 1, 2, 4 whose columns are at most
/// kRefinementDepths times the thickest release column wide, halved while the mesh would exceed
/// kRefinementCellBudget cells.
constexpr double kRefinementDepths = 10;
constexpr double kRefinementCellBudget = 250000;

/// The refinement for a grid of cells `dx` wide whose mesh has `columns` columns of `layers`
/// layers unrefined: mesh.refinement when given (> 0), else the rule. `reason` says which, with the
/// rule's figures.
int choose_refinement(int asked, double dx, double max_vertical_m, long columns, int layers, std::string& reason);

struct TerrainSetup {
  terrain::Grid grid;
  terrain::DemReport dem;
  terrain::ReleaseReport release;
  std::vector<double> h0;         ///< the release's thickness normal to the ground per grid cell
  std::vector<double> vertical;   ///< the same vertically (the depth-averaged engine's H)
  std::vector<double> cos_slope;  ///< per grid cell
  terrain::ColumnMeshSpec spec;    ///< its refinement chosen by choose_refinement
  std::string refinement_reason;
  Corridor corridor;               ///< the columns meshed (mesh.corridor)
  int domain_columns = 0;          ///< the columns inside the domain (refined)
  terrain::ColumnMesh columns_mesh;  ///< with the structures stood on it (terrain::place_structures)
  std::vector<std::string> structure_names;  ///< per structure (scenario structures[]); patches structure_patch(name)
  Frame frame;
  Columns columns;
  engine::vof::Mesh mesh;
  engine::vof::MeshQuality quality;
  std::vector<std::uint8_t> corridor_edge;  ///< per face: 1 on the corridor's edge (corridor_edge_faces)
  std::vector<double> alpha;  ///< the release's phase fraction per cell
  double volume_on_mesh = 0;  ///< sum alpha V [m3]
  std::vector<NamedPoint> points;
  OutputInputs output_inputs;  ///< what the hazard outputs read besides the run
};

/// Builds the set-up. Throws ScenarioError or terrain::TerrainError naming the field for bad input.
void build_terrain_setup(const ResolvedScenario& r, TerrainSetup& out);

}  // namespace runout::jobs::vof_terrain
