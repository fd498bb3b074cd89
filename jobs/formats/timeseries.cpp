#include "jobs/formats/timeseries.hpp"

#include <hdf5.h>

#include <array>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>

#include "jobs/formats/h5_attr.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs {

// The HDF5 library Debian builds with MPI (the one PETSc uses) is not thread-safe: the service runs
// several jobs in one process, so every HDF5 call holds this lock.
std::mutex& hdf5_mutex() {
  static std::mutex m;
  return m;
}

struct TimeSeriesWriter::Impl {
  std::string dir;
  terrain::Grid grid;
  int nx = 0, ny = 0;
  double flow_threshold = 0;
  engine::SurfaceGeometry geo;
  hid_t file = -1;
  std::vector<double> times;

  // Where the frames go and on which grid (its origin, cells and surface geometry).
  void place(const std::string& directory, const terrain::Grid& g, const engine::Terrain2D& t, double threshold) {
    dir = directory;
    grid = g;
    nx = g.nx;
    ny = g.ny;
    flow_threshold = threshold;
    geo = engine::SurfaceGeometry::from(t);
  }

  // A (ny, nx[, 3]) dataset of `file_type`, chunked and compressed.
  template <class T>
  void dataset(hid_t loc, const char* name, const std::vector<T>& v, hid_t file_type, hid_t mem_type, int depth = 1) {
    const hsize_t dims[3] = {hsize_t(ny), hsize_t(nx), hsize_t(depth)};
    hid_t space = H5Screate_simple(depth > 1 ? 3 : 2, dims, nullptr);
    hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
    const hsize_t chunk[3] = {hsize_t(std::min(ny, 256)), hsize_t(std::min(nx, 256)), hsize_t(depth)};
    H5Pset_chunk(plist, depth > 1 ? 3 : 2, chunk);
    H5Pset_deflate(plist, 4);
    hid_t ds = H5Dcreate2(loc, name, file_type, space, H5P_DEFAULT, plist, H5P_DEFAULT);
    if (ds < 0) throw std::runtime_error(std::string("time series: cannot create dataset ") + name);
    const herr_t st = H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(ds);
    H5Pclose(plist);
    H5Sclose(space);
    if (st < 0) throw std::runtime_error(std::string("time series: cannot write dataset ") + name);
  }
  void dataset(hid_t loc, const char* name, const std::vector<float>& v) { dataset(loc, name, v, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT); }

  // One frame's field back from the file (row 0 south), NaN kept.
  std::vector<double> read_frame(hid_t f, std::size_t frame, const char* field) const {
    char name[48];
    std::snprintf(name, sizeof name, "frames/%05zu/%s", frame, field);
    std::vector<double> v(std::size_t(nx) * ny);
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    const herr_t st = ds < 0 ? -1 : H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    if (ds >= 0) H5Dclose(ds);
    if (st < 0) throw std::runtime_error(std::string("time series: cannot read ") + name);
    return v;
  }

  // The volume-weighted centre of a frame's depth (normal depth over the surface's cosine: the
  // column's volume per plan area).
  std::array<double, 3> mass_centre(double t, const std::vector<double>& depth) const {
    double m = 0, mx = 0, my = 0;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t k = std::size_t(j) * nx + i;
        if (!(depth[k] > 0)) continue;
        const double w = depth[k] / geo.c[k];
        m += w;
        mx += w * grid.cx(i);
        my += w * grid.cy(j);
      }
    return {t, m > 0 ? mx / m : NAN, m > 0 ? my / m : NAN};
  }

  void write_xdmf() const;
  void write_geotiffs();
  std::vector<std::array<double, 3>> track;  ///< t, x, y of each frame's mass centre (after finish)
};

TimeSeriesWriter::TimeSeriesWriter(const std::string& dir, const terrain::Grid& grid, const engine::Terrain2D& t, double flow_threshold)
    : impl_(std::make_unique<Impl>()) {
  auto& m = *impl_;
  m.place(dir, grid, t, flow_threshold);
  std::lock_guard lk(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by us
  m.file = H5Fcreate((dir + "/timeseries.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (m.file < 0) throw std::runtime_error("time series: cannot create " + dir + "/timeseries.h5");
  std::vector<float> z(grid.cells());
  for (std::size_t k = 0; k < z.size(); ++k) z[k] = float(grid.z[k]);
  m.dataset(m.file, "elevation", z);
  // The terrain surface for ParaView: x, y, z of each cell centre in the grid's CRS, z up (Float64:
  // UTM northings need more than Float32's 24 bits).
  std::vector<double> xyz(3 * grid.cells());
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      const std::size_t k = std::size_t(j) * grid.nx + i;
      xyz[3 * k] = grid.cx(i);
      xyz[3 * k + 1] = grid.cy(j);
      xyz[3 * k + 2] = grid.z[k];
    }
  m.dataset(m.file, "surface", xyz, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 3);
  hid_t g = H5Gcreate2(m.file, "frames", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Gclose(g);
}

TimeSeriesWriter::TimeSeriesWriter(const std::string& dir, const terrain::Grid& grid, const engine::Terrain2D& t, double flow_threshold,
                                   const std::string& continue_from, int frames)
    : impl_(std::make_unique<Impl>()) {
  auto& m = *impl_;
  m.place(dir, grid, t, flow_threshold);
  const std::string path = dir + "/timeseries.h5";
  std::lock_guard lk(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (!std::filesystem::is_regular_file(continue_from) || H5Fis_hdf5(continue_from.c_str()) <= 0)
    throw ScenarioError("the checkpoint's time series " + continue_from + " is missing or not HDF5 (it is written beside the checkpoint)");
  std::error_code ec;
  std::filesystem::copy_file(continue_from, path, std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) throw std::runtime_error("time series: cannot copy " + continue_from + " to " + path + ": " + ec.message());
  m.file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  if (m.file < 0) throw ScenarioError("the checkpoint's time series " + continue_from + ": cannot open it");
  char name[32];
  for (int f = 0; f < frames; ++f) {
    std::snprintf(name, sizeof name, "frames/%05d", f);
    double time = 0;
    hid_t a = H5Lexists(m.file, name, H5P_DEFAULT) > 0 ? H5Aopen_by_name(m.file, name, "time", H5P_DEFAULT, H5P_DEFAULT) : -1;
    const herr_t st = a < 0 ? -1 : H5Aread(a, H5T_NATIVE_DOUBLE, &time);
    if (a >= 0) H5Aclose(a);
    if (st < 0) throw ScenarioError("the checkpoint's time series " + continue_from + " lacks frame " + std::to_string(f));
    m.times.push_back(time);
  }
  // Frames written after the checkpoint was taken (a run killed between the two writes) go.
  for (int f = frames;; ++f) {
    std::snprintf(name, sizeof name, "frames/%05d", f);
    if (H5Lexists(m.file, name, H5P_DEFAULT) <= 0) break;
    if (H5Ldelete(m.file, name, H5P_DEFAULT) < 0) throw std::runtime_error("time series: cannot drop frame " + std::string(name));
  }
}

int TimeSeriesWriter::frames() const { return int(impl_->times.size()); }

const std::vector<std::array<double, 3>>& TimeSeriesWriter::mass_centres() const { return impl_->track; }

void TimeSeriesWriter::save_copy(const std::string& path) {
  auto& m = *impl_;
  const std::string tmp = path + ".part";
  {
    std::lock_guard lk(hdf5_mutex());
    if (m.file < 0 || H5Fflush(m.file, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error("time series: cannot flush " + m.dir + "/timeseries.h5");
    std::error_code ec;
    std::filesystem::copy_file(m.dir + "/timeseries.h5", tmp, std::filesystem::copy_options::overwrite_existing, ec);
    if (ec) throw std::runtime_error("time series: cannot copy the frames to " + tmp + ": " + ec.message());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("time series: cannot move the frames into place at " + path + ": " + ec.message());
}

TimeSeriesWriter::~TimeSeriesWriter() {
  std::lock_guard lk(hdf5_mutex());
  if (impl_ && impl_->file >= 0) H5Fclose(impl_->file);
}

void TimeSeriesWriter::write(double t, const engine::Sh2dStateView& s) {
  auto& m = *impl_;
  const std::size_t n = std::size_t(m.nx) * m.ny;
  std::vector<float> h(n), sp(n, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t k = 0; k < n; ++k) {
    const double H = s.H[k];
    h[k] = float(H * m.geo.c[k]);
    if (H * m.geo.c[k] > m.flow_threshold) {  // speed where it flows, as in max_speed.tif
      const double w = m.geo.bx[k] * s.HU[k] + m.geo.by[k] * s.HV[k];
      sp[k] = float(std::sqrt(s.HU[k] * s.HU[k] + s.HV[k] * s.HV[k] + w * w) / H);
    }
  }
  char name[32];
  std::snprintf(name, sizeof name, "frames/%05zu", m.times.size());
  std::lock_guard lk(hdf5_mutex());
  hid_t g = H5Gcreate2(m.file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) throw std::runtime_error("time series: cannot create group");
  m.dataset(g, "depth", h);
  m.dataset(g, "speed", sp);
  h5::put_attr_double(g, "time", t);
  H5Gclose(g);
  m.times.push_back(t);
}

int TimeSeriesWriter::finish() {
  auto& m = *impl_;
  {
    std::lock_guard lk(hdf5_mutex());
    if (m.file >= 0) H5Fclose(m.file);
    m.file = -1;
  }
  m.write_xdmf();
  m.write_geotiffs();
  return int(m.times.size());
}

void TimeSeriesWriter::Impl::write_xdmf() const {
  std::ofstream x(dir + "/timeseries.xmf");
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n";
  x << "  <Grid Name=\"runout\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  char buf[256];
  for (std::size_t f = 0; f < times.size(); ++f) {
    x << "   <Grid Name=\"frame" << f << "\" GridType=\"Uniform\">\n";
    x << "    <Time Value=\"" << times[f] << "\"/>\n";
    // The terrain surface through the cell centres, in the grid's CRS with z up: the data are node
    // values on it.
    x << "    <Topology TopologyType=\"2DSMesh\" Dimensions=\"" << ny << " " << nx << "\"/>\n";
    x << "    <Geometry GeometryType=\"XYZ\">\n     <DataItem Dimensions=\"" << ny << " " << nx
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">timeseries.h5:/surface</DataItem>\n    </Geometry>\n";
    for (const char* a : {"depth", "speed"}) {
      std::snprintf(buf, sizeof buf, "timeseries.h5:/frames/%05zu/%s", f, a);
      x << "    <Attribute Name=\"" << a << "\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\""
        << ny << " " << nx << "\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << buf << "</DataItem>\n    </Attribute>\n";
    }
    x << "    <Attribute Name=\"elevation\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\"" << ny
      << " " << nx << "\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">timeseries.h5:/elevation</DataItem>\n    </Attribute>\n";
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  if (!x) throw std::runtime_error("time series: cannot write timeseries.xmf");
}

// The frames as georeferenced multi-band GeoTIFFs, read back from the HDF5 file one band at a time.
void TimeSeriesWriter::Impl::write_geotiffs() {
  std::vector<terrain::BandInfo> depth, speed;
  std::string all;
  char t[32];
  for (double time : times) {
    std::snprintf(t, sizeof t, "%.10g", time);
    depth.push_back({std::string("flow depth normal to the surface at t = ") + t + " s [m]", "m", {{"TIME_S", t}}});
    speed.push_back({std::string("flow speed at t = ") + t + " s (where the depth exceeds the flow threshold) [m/s]", "m/s", {{"TIME_S", t}}});
    all += (all.empty() ? "" : ",") + std::string(t);
  }
  if (times.empty()) return;
  track.clear();
  for (auto [field, bands] : {std::pair<const char*, const std::vector<terrain::BandInfo>*>{"depth", &depth}, {"speed", &speed}}) {
    // The frames are read with the project's HDF5 (MPI build) under the lock; GDAL's netCDF driver
    // writes NetCDF-4 through Debian's serial HDF5, a library of its own (versioned symbols), so the
    // lock is held for the reads, not for that library's sake.
    std::lock_guard lk(hdf5_mutex());
    hid_t f = H5Fopen((dir + "/timeseries.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) throw std::runtime_error("time series: cannot reopen " + dir + "/timeseries.h5");
    try {
      terrain::write_band_stack(dir + "/timeseries_" + field + ".tif", grid, *bands,
                                [&](std::size_t b) {
                                  auto v = read_frame(f, b, field);
                                  if (field == std::string("depth")) track.push_back(mass_centre(times[b], v));
                                  return v;
                                },
                                {{"TIMES_S", all}});
      // The same frames as one CF NetCDF file with a time axis (QGIS's temporal controller), once.
      if (field == std::string("speed"))
        terrain::write_time_cube(dir + "/timeseries.nc", grid, times,
                                 {{"depth", "flow depth normal to the surface", "m", [&](std::size_t b) { return read_frame(f, b, "depth"); }},
                                  {"speed", "flow speed where the depth exceeds the flow threshold", "m/s",
                                   [&](std::size_t b) { return read_frame(f, b, "speed"); }}});
    } catch (...) {
      H5Fclose(f);
      throw;
    }
    H5Fclose(f);
  }
}

}  // namespace runout::jobs
