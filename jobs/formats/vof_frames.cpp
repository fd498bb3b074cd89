#include "jobs/formats/vof_frames.hpp"

#include <hdf5.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "jobs/formats/h5_attr.hpp"
#include "jobs/formats/timeseries.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs {

namespace vof = engine::vof;

VofFrameWriter::VofFrameWriter(const std::string& dir, const FrameGrid& g, const std::vector<vof::Vec>* centres, std::string work,
                               const std::string& continue_from, double t_restart)
    : dir_(dir), work_(work.empty() ? dir + "/fields.h5" : std::move(work)), g_(g) {
  std::lock_guard lk(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  curvilinear_ = centres && g.three_d;
  if (!continue_from.empty()) {
    continue_frames(continue_from, t_restart);
    return;
  }
  file_ = H5Fcreate(work_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) throw std::runtime_error("cannot create " + work_);
  if (curvilinear_) write_centres(*centres);
}

// The frames written before the checkpoint: without them the results would lack the run's start, so
// a missing or unreadable file is an error, not a fresh file. Keeps the frames up to the checkpoint's
// time, in order, and drops the later ones.
void VofFrameWriter::continue_frames(const std::string& continue_from, double t_restart) {
  if (!std::filesystem::is_regular_file(continue_from) || H5Fis_hdf5(continue_from.c_str()) <= 0)
    throw ScenarioError("the checkpoint's frames " + continue_from + " are missing or not HDF5 (they are written beside the checkpoint)");
  std::error_code ec;
  if (std::filesystem::weakly_canonical(continue_from, ec) != std::filesystem::weakly_canonical(work_, ec))
    std::filesystem::copy_file(continue_from, work_, std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) throw std::runtime_error("cannot copy the frames " + continue_from + " to " + work_ + ": " + ec.message());
  file_ = H5Fopen(work_.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  if (file_ < 0) throw ScenarioError("the checkpoint's frames " + continue_from + ": cannot open them");
  bool dropping = false;
  for (std::size_t f = 0;; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "f%05zu", f);
    if (H5Lexists(file_, name, H5P_DEFAULT) <= 0) break;
    double t = NAN;
    hid_t gr = H5Gopen2(file_, name, H5P_DEFAULT);
    if (gr >= 0) {
      t = h5::get_attr_double(gr, "t");
      H5Gclose(gr);
    }
    if (std::isnan(t)) {
      H5Fclose(file_);
      file_ = -1;
      throw ScenarioError("the checkpoint's frames " + continue_from + ": frame " + name + " has no time");
    }
    dropping = dropping || t > t_restart + 1e-12;
    if (dropping) H5Ldelete(file_, name, H5P_DEFAULT);
    else times_.push_back(t);
  }
}

void VofFrameWriter::write_centres(const std::vector<vof::Vec>& centres) {
  const auto& g = g_;
  std::vector<double> xyz(3 * g.cell.size(), NAN);
  for (std::size_t q = 0; q < g.cell.size(); ++q)
    if (const int c = g.cell[q]; c >= 0) {
      const auto& v = centres[std::size_t(c)];
      if (g.georeferenced) xyz[3 * q] = g.origin_east + v.x, xyz[3 * q + 1] = g.origin_north - v.z, xyz[3 * q + 2] = g.origin_elevation + v.y;
      else xyz[3 * q] = v.x, xyz[3 * q + 1] = v.y, xyz[3 * q + 2] = v.z;
    }
  const hsize_t dims[4] = {hsize_t(g.nz), hsize_t(g.ny), hsize_t(g.nx), 3};
  hid_t sp = H5Screate_simple(4, dims, nullptr);
  // Georeferenced centres in Float64: projected coordinates of millions of metres keep their
  // centimetres; a chute's in Float32 as its fields.
  hid_t ds = H5Dcreate2(file_, "centres", g.georeferenced ? H5T_IEEE_F64LE : H5T_IEEE_F32LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t st = H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, xyz.data());
  H5Dclose(ds);
  H5Sclose(sp);
  if (st < 0) {
    H5Fclose(file_);
    file_ = -1;
    throw std::runtime_error("fields.h5: writing the cell centres failed");
  }
}

VofFrameWriter::~VofFrameWriter() {
  std::lock_guard lk(hdf5_mutex());
  if (file_ >= 0) H5Fclose(file_);
}

void VofFrameWriter::write(double t, const vof::VofBackend& s) {
  const auto n = g_.cell.size();
  std::vector<float> a(n, NAN), ux(n, NAN), uy(n, NAN), uz(n, NAN), p(n, NAN), nu(n, NAN);
  for (std::size_t q = 0; q < n; ++q) {
    const int c = g_.cell[q];
    if (c < 0) continue;
    const auto k = std::size_t(c);
    a[q] = float(s.alpha()[k]);
    const auto& u = s.velocity()[k];
    ux[q] = float(u.x);
    uy[q] = float(g_.georeferenced ? -u.z : u.y);  // north
    uz[q] = float(g_.georeferenced ? u.y : u.z);   // up
    p[q] = float(s.pressure()[k]);
    nu[q] = float(s.viscosity()[k]);
  }
  std::lock_guard lk(hdf5_mutex());
  char name[32];
  std::snprintf(name, sizeof name, "/f%05zu", times_.size());
  hid_t gr = H5Gcreate2(file_, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (gr < 0) throw std::runtime_error("fields.h5: cannot create a frame");
  const hsize_t dims[3] = {hsize_t(g_.nz), hsize_t(g_.ny), hsize_t(g_.nx)};
  std::vector<std::pair<const char*, std::vector<float>*>> sets = {{"alpha", &a}, {"ux", &ux}, {"uy", &uy}, {"p", &p}, {"nu", &nu}};
  if (g_.three_d) sets.push_back({"uz", &uz});
  for (auto [nm, v] : sets) {
    hid_t sp = g_.three_d ? H5Screate_simple(3, dims, nullptr) : H5Screate_simple(2, dims + 1, nullptr);
    hid_t ds = H5Dcreate2(gr, nm, H5T_IEEE_F32LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const herr_t st = H5Dwrite(ds, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v->data());
    H5Dclose(ds);
    H5Sclose(sp);
    if (st < 0) {
      H5Gclose(gr);
      throw std::runtime_error("fields.h5: writing failed");
    }
  }
  if (!h5::put_attr_double(gr, "t", t)) {
    H5Gclose(gr);
    throw std::runtime_error("fields.h5: writing a frame's time failed");
  }
  H5Gclose(gr);
  H5Fflush(file_, H5F_SCOPE_LOCAL);  // a checkpoint taken now finds the frame on disk
  times_.push_back(t);
}

int VofFrameWriter::finish() {
  {
    std::lock_guard lk(hdf5_mutex());
    if (file_ >= 0) H5Fclose(file_);
    file_ = -1;
  }
  if (work_ != dir_ + "/fields.h5") {
    // Copied, not moved: the frames stay beside the checkpoint, which may continue the run later
    // (to a later end time).
    std::error_code ec;
    std::filesystem::copy_file(work_, dir_ + "/fields.h5", std::filesystem::copy_options::overwrite_existing, ec);
    if (ec) throw std::runtime_error("cannot copy the frames " + work_ + " to " + dir_ + "/fields.h5: " + ec.message());
  }
  write_xdmf();
  return int(times_.size());
}

// fields.xmf: a temporal collection on the cell centres (ORIGIN_DXDY, ORIGIN_DXDYDZ in 3D).
void VofFrameWriter::write_xdmf() const {
  const auto& g = g_;
  std::ostringstream dims;
  if (g.three_d) dims << g.nz << " " << g.ny << " " << g.nx;
  else dims << g.ny << " " << g.nx;
  std::ofstream x(dir_ + "/fields.xmf");
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n  <Grid Name=\"lab\" GridType=\"Collection\" "
       "CollectionType=\"Temporal\">\n";
  for (std::size_t f = 0; f < times_.size(); ++f) {
    char grp[32];
    std::snprintf(grp, sizeof grp, "f%05zu", f);
    x << "   <Grid Name=\"" << grp << "\" GridType=\"Uniform\">\n    <Time Value=\"" << times_[f] << "\"/>\n";
    if (curvilinear_) {  // the values at the cell centres as they lie (a curved chute)
      x << "    <Topology TopologyType=\"3DSMesh\" Dimensions=\"" << dims.str() << "\"/>\n";
      x << "    <Geometry GeometryType=\"XYZ\">\n     <DataItem Dimensions=\"" << dims.str()
        << " 3\" NumberType=\"Float\" Precision=\"" << (g.georeferenced ? 8 : 4)
        << "\" Format=\"HDF\">fields.h5:/centres</DataItem>\n    </Geometry>\n";
    } else if (g.three_d) {
      x << "    <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" << dims.str() << "\"/>\n";
      x << "    <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n     <DataItem Dimensions=\"3\" Format=\"XML\">" << g.z0 + 0.5 * g.dz << " "
        << g.y0 + 0.5 * g.dy << " " << g.x0 + 0.5 * g.dx << "</DataItem>\n     <DataItem Dimensions=\"3\" Format=\"XML\">" << g.dz << " "
        << g.dy << " " << g.dx << "</DataItem>\n    </Geometry>\n";
    } else {
      x << "    <Topology TopologyType=\"2DCoRectMesh\" Dimensions=\"" << dims.str() << "\"/>\n";
      x << "    <Geometry GeometryType=\"ORIGIN_DXDY\">\n     <DataItem Dimensions=\"2\" Format=\"XML\">" << g.y0 + 0.5 * g.dy << " "
        << g.x0 + 0.5 * g.dx << "</DataItem>\n     <DataItem Dimensions=\"2\" Format=\"XML\">" << g.dy << " " << g.dx
        << "</DataItem>\n    </Geometry>\n";
    }
    std::vector<const char*> names = {"alpha", "ux", "uy", "p", "nu"};
    if (g.three_d) names.push_back("uz");
    for (const char* a : names)
      x << "    <Attribute Name=\"" << a << "\" AttributeType=\"Scalar\" Center=\"Node\">\n     <DataItem Dimensions=\"" << dims.str()
        << "\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">fields.h5:/" << grp << "/" << a << "</DataItem>\n    </Attribute>\n";
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  if (!x) throw std::runtime_error("cannot write fields.xmf");
}

}  // namespace runout::jobs
