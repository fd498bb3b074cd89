#pragma once
// Time series of a run: HDF5 (one group per frame: normal depth and speed, Float32; the terrain
// surface as x, y, z of the cell centres in the grid's CRS) with an XDMF file that describes them as
// a temporal collection on the terrain surface, z up (ParaView); and, for QGIS and every GDAL reader,
// georeferenced multi-band Cloud Optimized GeoTIFFs of the frames (timeseries_depth.tif,
// timeseries_speed.tif, one band per frame with its time) and the same frames as one CF NetCDF file
// with a time axis (timeseries.nc: QGIS's temporal controller steps through it). Speeds are masked
// (NaN, nodata) where the depth is at most the flow threshold, as in the maximum-speed map.
#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "terrain/terrain.hpp"

namespace runout::jobs {

/// The process-wide lock every HDF5 call holds (the MPI build of HDF5 is not thread-safe).
std::mutex& hdf5_mutex();

class TimeSeriesWriter {
 public:
  /// Creates `<dir>/timeseries.h5` with the grid and the terrain. Throws std::runtime_error.
  TimeSeriesWriter(const std::string& dir, const terrain::Grid& grid, const engine::Terrain2D& terrain, double flow_threshold);
  /// Continues the time series of an interrupted run: `<dir>/timeseries.h5` becomes a copy of
  /// `continue_from` (a file save_copy wrote) with its first `frames` frames (later ones are
  /// dropped), and the frames written next follow them. Throws ScenarioError when it lacks them.
  TimeSeriesWriter(const std::string& dir, const terrain::Grid& grid, const engine::Terrain2D& terrain, double flow_threshold,
                   const std::string& continue_from, int frames);
  ~TimeSeriesWriter();
  TimeSeriesWriter(const TimeSeriesWriter&) = delete;
  TimeSeriesWriter& operator=(const TimeSeriesWriter&) = delete;

  /// Append one frame (state as the solver holds it).
  void write(double t, const engine::Sh2dStateView& s);
  /// Close the HDF5 file and write `<dir>/timeseries.xmf` and the GeoTIFFs of the frames. Returns the
  /// number of frames.
  int finish();
  /// Frames written so far.
  int frames() const;
  /// After finish: per frame, its time and the flow's volume-weighted mass centre (t, x, y in the
  /// grid's CRS; x, y NaN for a frame without flow).
  const std::vector<std::array<double, 3>>& mass_centres() const;
  /// Put a copy of the frames so far at `path` (atomically: a temporary file renamed), for a
  /// checkpoint taken now. Throws std::runtime_error.
  void save_copy(const std::string& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace runout::jobs
