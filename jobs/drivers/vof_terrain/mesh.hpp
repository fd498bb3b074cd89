#pragma once
// The VOF engine's mesh over real terrain: the column mesh of terrain/column_mesh.hpp as hexahedra
// in the engine's frame. The engine's frame is right-handed with y up, as the laboratory set-ups'
// (gravity along -y): x east, y the elevation above `origin.z`, z south, in metres from the grid's
// centre. Patches: "ground" (the bottom of every column), "atmosphere" (the top), "sides" (the
// grid's edges and the faces towards columns outside the domain).
#include "engine/vof/mesh.hpp"
#include "terrain/column_mesh.hpp"

namespace runout::jobs::vof_terrain {

/// Where the engine's frame lies in the grid's CRS: x = east - origin.x, y = elevation - origin.z,
/// z = origin.y - north.
struct Frame {
  double x = 0, y = 0, z = 0;
  engine::vof::Vec to_engine(double east, double north, double elevation) const { return {east - x, elevation - z, y - north}; }
};

/// The frame of a column mesh: the grid's centre, the lowest ground node.
Frame frame_of(const terrain::ColumnMesh& c);

/// The engine's mesh of the kept columns: i east, j up the layers, k north (cell (i, j, k) of the
/// engine's structured numbering with left-out columns skipped).
engine::vof::Mesh terrain_mesh(const terrain::ColumnMesh& c, const Frame& frame);

}  // namespace runout::jobs::vof_terrain
