#include "jobs/timeseries.hpp"

#include <hdf5.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <stdexcept>

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
  m.dir = dir;
  m.nx = grid.nx;
  m.ny = grid.ny;
  m.dx = grid.dx;
  m.x0 = grid.x_min;
  m.y0 = grid.y_min;
  m.geo = engine::SurfaceGeometry::from(t);
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
  hid_t space = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(g, "time", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(a);
  H5Sclose(space);
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
