#pragma once
// Frames of a VOF laboratory run for ParaView: fields.h5 (one group per frame: alpha, velocity,
// pressure and granular viscosity on the lab block's grid, Float32, blocked cells NaN) plus
// fields.xmf, a temporal collection on the cell centres (co-rectilinear, or the cell centres as they
// lie on a curved chute or over terrain, there in the grid's CRS with z up). The depth-averaged engine's counterpart is timeseries.hpp; both hold
// hdf5_mutex() for every HDF5 call.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/vof/backend.hpp"

namespace runout::jobs {

/// The lab block as a grid: nx x ny (x nz in 3D) cells, row-major with j = 0 at the bottom and k = 0
/// at z_min; `cell` maps a grid position to the mesh cell, -1 where an obstacle blocks it.
struct FrameGrid {
  int nx = 0, ny = 0, nz = 1;
  bool three_d = false;
  double x0 = 0, y0 = 0, z0 = 0, dx = 0, dy = 0, dz = 0;
  std::vector<int> cell;
  /// Terrain runs: the engine's frame (x east, y up, z south, from `origin`) written in the grid's
  /// CRS, z up: the cell centres (east, north, elevation; Float64) and the velocity (east, north, up).
  bool georeferenced = false;
  double origin_east = 0, origin_north = 0, origin_elevation = 0;
  std::size_t at(int i, int j, int k) const { return (std::size_t(k) * std::size_t(ny) + std::size_t(j)) * std::size_t(nx) + std::size_t(i); }
  int id(int i, int j, int k) const { return cell[at(i, j, k)]; }
};

class VofFrameWriter {
 public:
  /// `centres`: for a mesh that is not the lab block's box (a curved chute), the mesh's cell
  /// centres, written once as /centres so that fields.xmf places the values where they are.
  /// `work`: where the frames are written while the run goes on (empty: dir/fields.h5; a run with
  /// checkpoints keeps them next to its checkpoint, so that a continued run has them); finish()
  /// copies them to dir/fields.h5. `continue_from`: a frames file of an interrupted run; its frames up
  /// to `t_restart` are kept and the run's frames follow them. Throws ScenarioError when that file
  /// is missing or damaged, std::runtime_error when writing fails.
  VofFrameWriter(const std::string& dir, const FrameGrid& g, const std::vector<engine::vof::Vec>* centres = nullptr, std::string work = {},
                 const std::string& continue_from = {}, double t_restart = 0);
  ~VofFrameWriter();
  VofFrameWriter(const VofFrameWriter&) = delete;
  VofFrameWriter& operator=(const VofFrameWriter&) = delete;

  /// Append the solver's state as frame at time t.
  void write(double t, const engine::vof::VofBackend& s);
  /// Close fields.h5 (copied to dir when written elsewhere) and write fields.xmf. Returns the
  /// number of frames.
  int finish();

 private:
  void continue_frames(const std::string& continue_from, double t_restart);
  void write_centres(const std::vector<engine::vof::Vec>& centres);
  void write_xdmf() const;

  std::string dir_, work_;
  const FrameGrid& g_;
  std::int64_t file_ = -1;  ///< the HDF5 file (hid_t)
  std::vector<double> times_;
  bool curvilinear_ = false;
};

}  // namespace runout::jobs
