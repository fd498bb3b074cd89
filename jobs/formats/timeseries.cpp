#include "jobs/formats/timeseries.hpp"

#include <hdf5.h>

#include <cmath>
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
  int nx = 0, ny = 0;
  double dx = 0, x0 = 0, y0 = 0;
  engine::SurfaceGeometry geo;
  hid_t file = -1;
  std::vector<double> times;

  // Where the frames go and on which grid (its origin, cells and surface geometry).
  void place(const std::string& directory, const terrain::Grid& grid, const engine::Terrain2D& t) {
    dir = directory;
    nx = grid.nx;
    ny = grid.ny;
    dx = grid.dx;
    x0 = grid.x_min;
    y0 = grid.y_min;
    geo = engine::SurfaceGeometry::from(t);
  }

  void dataset(hid_t loc, const char* name, const std::vector<float>& v) {
    const hsize_t dims[2] = {hsize_t(ny), hsize_t(nx)};
    hid_t space = H5Screate_simple(2, dims, nullptr);
    hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
    const hsize_t chunk[2] = {hsize_t(std::min(ny, 256)), hsize_t(std::min(nx, 256))};
    H5Pset_chunk(plist, 2, chunk);
    H5Pset_deflate(plist, 4);
    hid_t ds = H5Dcreate2(loc, name, H5T_IEEE_F32LE, space, H5P_DEFAULT, plist, H5P_DEFAULT);
    if (ds < 0) throw std::runtime_error(std::string("time series: cannot create dataset ") + name);
    const herr_t st = H5Dwrite(ds, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(ds);
    H5Pclose(plist);
    H5Sclose(space);
    if (st < 0) throw std::runtime_error(std::string("time series: cannot write dataset ") + name);
  }
};

TimeSeriesWriter::TimeSeriesWriter(const std::string& dir, const terrain::Grid& grid, const engine::Terrain2D& t)
    : impl_(std::make_unique<Impl>()) {
  auto& m = *impl_;
  m.place(dir, grid, t);
  std::lock_guard lk(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by us
  m.file = H5Fcreate((dir + "/timeseries.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (m.file < 0) throw std::runtime_error("time series: cannot create " + dir + "/timeseries.h5");
  std::vector<float> z(grid.cells());
  for (std::size_t k = 0; k < z.size(); ++k) z[k] = float(grid.z[k]);
  m.dataset(m.file, "elevation", z);
  hid_t g = H5Gcreate2(m.file, "frames", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Gclose(g);
}

TimeSeriesWriter::TimeSeriesWriter(const std::string& dir, const terrain::Grid& grid, const engine::Terrain2D& t,
                                   const std::string& continue_from, int frames)
    : impl_(std::make_unique<Impl>()) {
  auto& m = *impl_;
  m.place(dir, grid, t);
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
  std::vector<float> h(n), sp(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double H = s.H[k];
    h[k] = float(H * m.geo.c[k]);
    if (H > 1e-8) {
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
  if (m.file >= 0) {
    std::lock_guard lk(hdf5_mutex());
    H5Fclose(m.file);
    m.file = -1;
  }
  std::ofstream x(m.dir + "/timeseries.xmf");
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n";
  x << "  <Grid Name=\"runout\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  char buf[256];
  for (std::size_t f = 0; f < m.times.size(); ++f) {
    x << "   <Grid Name=\"frame" << f << "\" GridType=\"Uniform\">\n";
    x << "    <Time Value=\"" << m.times[f] << "\"/>\n";
    // Nodes of the cell-centred grid: the data are node values on the mesh of cell centres.
    x << "    <Topology TopologyType=\"2DCoRectMesh\" Dimensions=\"" << m.ny << " " << m.nx << "\"/>\n";
    std::snprintf(buf, sizeof buf, "%.6f %.6f", m.y0 + 0.5 * m.dx, m.x0 + 0.5 * m.dx);
    x << "    <Geometry GeometryType=\"ORIGIN_DXDY\">\n     <DataItem Dimensions=\"2\" Format=\"XML\">" << buf
      << "</DataItem>\n";
    x << "     <DataItem Dimensions=\"2\" Format=\"XML\">" << m.dx << " " << m.dx << "</DataItem>\n    </Geometry>\n";
    for (const char* a : {"depth", "speed"}) {
      std::snprintf(buf, sizeof buf, "timeseries.h5:/frames/%05zu/%s", f, a);
      x << "    <Attribute Name=\"" << a << "\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\""
        << m.ny << " " << m.nx << "\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">" << buf << "</DataItem>\n    </Attribute>\n";
    }
    x << "    <Attribute Name=\"elevation\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\"" << m.ny
      << " " << m.nx << "\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">timeseries.h5:/elevation</DataItem>\n    </Attribute>\n";
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  if (!x) throw std::runtime_error("time series: cannot write timeseries.xmf");
  return int(m.times.size());
}

}  // namespace runout::jobs
