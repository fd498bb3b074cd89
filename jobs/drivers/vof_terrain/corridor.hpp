#pragma once
// The corridor of the 3D engine's mesh on the DEM (mesh.corridor): the grid cells whose columns are
// meshed, inside the domain.
//   - "footprint" (default): the depth-averaged engine run on the same grid, release, material and
//     numerics (as jobs/drivers/run.cpp runs it), the cells whose maximum flow depth exceeded
//     outputs.flow_threshold_m, and the release's cells, dilated by mesh.corridor_margin_m (default
//     150 m or two cells, whichever is wider: corridor_margin());
//   - "polygon": the cells whose centres lie inside the polygons of mesh.corridor_path; every release
//     cell must be among them;
//   - "none": every column of the domain.
// The faces towards a column of the domain left out of the corridor are the mesh's "sides" (an
// atmosphere condition): what leaves through them is counted apart from the domain's edge
// (corridor_edge_faces) and reported in run.json.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/vof/mesh.hpp"
#include "jobs/drivers/vof_terrain/mesh.hpp"
#include "jobs/scenario/scenario.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs::vof_terrain {

struct Corridor {
  std::string kind = "none";  ///< "footprint", "polygon" or "none"
  double margin_m = 0;        ///< "footprint": the dilation [m]
  std::string path;           ///< "polygon": the file
  std::vector<std::uint8_t> cells;  ///< per grid cell (row 0 south); empty for "none"
  int footprint_cells = 0;          ///< "footprint": cells above the flow threshold (release included)
  double footprint_seconds = 0;     ///< "footprint": wall time of the depth-averaged run
};

/// The footprint's dilation: mesh.corridor_margin_m when given, else 150 m or two cells of dx,
/// whichever is wider.
double corridor_margin(const v1::TerrainMesh& m, double dx);

/// The footprint corridor from a maximum-depth map: the cells with max_depth > threshold or a
/// release (h0 > 0), dilated by margin_m (terrain::dilate_cells). Returns the footprint's cell count
/// in `footprint_cells` when given.
std::vector<std::uint8_t> footprint_corridor(const terrain::Grid& g, const std::vector<double>& max_depth, double threshold,
                                             const std::vector<double>& h0, double margin_m, int* footprint_cells = nullptr);

/// The scenario's corridor on `g` for the release `h0` (normal thickness per cell). Throws
/// ScenarioError naming mesh.corridor_path and the file when the polygons leave release cells out or
/// cover no cell of the domain.
Corridor build_corridor(const ResolvedScenario& r, const terrain::Grid& g, const std::vector<double>& h0);

/// Per face of `m`: 1 for a face of the "sides" patch towards a column of the domain that is not
/// meshed (the corridor's edge), 0 otherwise (internal faces, the domain's or the grid's edge, the
/// ground and the top).
std::vector<std::uint8_t> corridor_edge_faces(const Columns& cols, const engine::vof::Mesh& m, const terrain::Grid& g);

}  // namespace runout::jobs::vof_terrain
