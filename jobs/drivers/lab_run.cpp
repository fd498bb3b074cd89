#include "jobs/drivers/lab_run.hpp"
#include "jobs/figures/lab_figure.hpp"

#include <gdal_priv.h>
#include <google/protobuf/util/json_util.h>
#include <hdf5.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <sstream>

#include "engine/vof/solver.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/digest/sha256.hpp"
#include "jobs/formats/timeseries.hpp"

namespace runout::jobs {

namespace {

namespace vof = engine::vof;
constexpr double kPi = 3.14159265358979323846;

struct Material {
  double rho, phi_deg, delta_deg;
};
Material material(const std::string& name) {  // validation.md part B
  if (name == "sand") return {1626.67, 37, 18};
  if (name == "fine-sand") return {1855, 54.5, 54.5};  // rotating box: side walls raise the effective phi
  return {936.17, 32, 20};
}


// The lab block as a grid: nx x ny (x nz in 3D) cells, row-major with j = 0 at the bottom and k = 0
// at z_min; `cell` maps a grid position to the mesh cell, -1 where an obstacle blocks it.
struct LabGrid {
  int nx = 0, ny = 0, nz = 1;
  bool three_d = false;
  double x0 = 0, y0 = 0, z0 = 0, dx = 0, dy = 0, dz = 0;
  double width = 0;  ///< across the channel: the modelled width in 3D, the plane mesh's thickness in 2D
  std::vector<int> cell;
  std::size_t at(int i, int j, int k) const { return (std::size_t(k) * std::size_t(ny) + std::size_t(j)) * std::size_t(nx) + std::size_t(i); }
  int id(int i, int j, int k) const { return cell[at(i, j, k)]; }
  int kc = 0;  ///< the slice along the centre line (stations, gate monitor)
};

// Obstacles of the lab block (validation.md B5, B7): is the point inside?
bool in_polygon(const google::protobuf::RepeatedField<double>& xy, double x, double y) {
  bool in = false;  // even-odd rule
  const int n = xy.size() / 2;
  for (int a = 0, b = n - 1; a < n; b = a++) {
    const double xa = xy.Get(2 * a), ya = xy.Get(2 * a + 1), xb = xy.Get(2 * b), yb = xy.Get(2 * b + 1);
    if ((ya > y) != (yb > y) && x < (xb - xa) * (y - ya) / (yb - ya) + xa) in = !in;
  }
  return in;
}

bool in_obstacle(const v1::LabObstacle& o, const vof::Vec& c, double y0) {
  if (o.shape() == "polygon") return in_polygon(o.polygon_xy(), c.x, c.y);
  if (o.shape() == "cylinder") return std::hypot(c.x - o.x(), c.z - o.z()) < o.radius() && c.y - y0 < o.height();
  // A regular tetrahedron standing on a face: footprint an equilateral triangle of edge a around
  // (x, z), apex at height a sqrt(2/3); "edge" puts a corner of the footprint upstream (the flow
  // meets the edge from it to the apex), "face" a side (the flow meets an inclined face).
  const double a = o.edge(), R = a / std::sqrt(3.0), H = a * std::sqrt(2.0 / 3.0);
  const double sgn = o.shape() == "tetrahedron-edge" ? -1 : 1;
  const vof::Vec v[4] = {{o.x() + sgn * R, y0, o.z()}, {o.x() - sgn * R / 2, y0, o.z() - a / 2}, {o.x() - sgn * R / 2, y0, o.z() + a / 2},
                         {o.x(), y0 + H, o.z()}};
  static const int faces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};  // three corners and the opposite one
  for (const auto& f : faces) {
    const vof::Vec e1 = v[f[1]] - v[f[0]], e2 = v[f[2]] - v[f[0]];
    const vof::Vec n{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
    const double side_opposite = vof::dot(n, v[f[3]] - v[f[0]]), side_c = vof::dot(n, c - v[f[0]]);
    if (side_c * side_opposite < 0) return false;
  }
  return true;
}

// Fields of the lab grid in one HDF5 file, frame by frame (blocked cells NaN).
class FieldWriter {
 public:
  /// `centres`: for a mesh that is not the lab block's box (a curved chute), the mesh's cell
  /// centres, written once as /centres so that fields.xmf places the values where they are.
  /// `work`: where the frames are written while the run goes on (empty: dir/fields.h5; a run with
  /// checkpoints keeps them next to its checkpoint, so that a continued run has them); finish()
  /// copies them to dir/fields.h5. `continue_from`: a frames file of an interrupted run; its frames up
  /// to `t_restart` are kept and the run's frames follow them.
  FieldWriter(const std::string& dir, const LabGrid& g, const std::vector<vof::Vec>* centres = nullptr, std::string work = {},
              const std::string& continue_from = {}, double t_restart = 0)
      : dir_(dir), work_(work.empty() ? dir + "/fields.h5" : std::move(work)), g_(g) {
    std::lock_guard lk(hdf5_mutex());
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    curvilinear_ = centres && g.three_d;
    if (!continue_from.empty()) {
      // The frames written before the checkpoint: without them the results would lack the run's
      // start, so a missing or unreadable file is an error, not a fresh file.
      if (!std::filesystem::is_regular_file(continue_from) || H5Fis_hdf5(continue_from.c_str()) <= 0)
        throw ScenarioError("the checkpoint's frames " + continue_from + " are missing or not HDF5 (they are written beside the checkpoint)");
      std::error_code ec;
      if (std::filesystem::weakly_canonical(continue_from, ec) != std::filesystem::weakly_canonical(work_, ec))
        std::filesystem::copy_file(continue_from, work_, std::filesystem::copy_options::overwrite_existing, ec);
      if (ec) throw std::runtime_error("cannot copy the frames " + continue_from + " to " + work_ + ": " + ec.message());
      file_ = H5Fopen(work_.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      if (file_ < 0) throw ScenarioError("the checkpoint's frames " + continue_from + ": cannot open them");
      // Keep the frames up to the checkpoint's time, in order; drop the later ones.
      bool dropping = false;
      for (std::size_t f = 0;; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "f%05zu", f);
        if (H5Lexists(file_, name, H5P_DEFAULT) <= 0) break;
        double t = NAN;
        hid_t gr = H5Gopen2(file_, name, H5P_DEFAULT);
        if (gr >= 0 && H5Aexists(gr, "t") > 0) {
          hid_t a = H5Aopen(gr, "t", H5P_DEFAULT);
          H5Aread(a, H5T_NATIVE_DOUBLE, &t);
          H5Aclose(a);
        }
        if (gr >= 0) H5Gclose(gr);
        if (std::isnan(t)) {
          H5Fclose(file_);
          file_ = -1;
          throw ScenarioError("the checkpoint's frames " + continue_from + ": frame " + name + " has no time");
        }
        dropping = dropping || t > t_restart + 1e-12;
        if (dropping) H5Ldelete(file_, name, H5P_DEFAULT);
        else times_.push_back(t);
      }
      return;
    }
    file_ = H5Fcreate(work_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file_ < 0) throw std::runtime_error("cannot create " + work_);
    if (curvilinear_) {
      std::vector<float> xyz(3 * g.cell.size(), NAN);
      for (std::size_t q = 0; q < g.cell.size(); ++q)
        if (const int c = g.cell[q]; c >= 0) {
          const auto& v = (*centres)[std::size_t(c)];
          xyz[3 * q] = float(v.x), xyz[3 * q + 1] = float(v.y), xyz[3 * q + 2] = float(v.z);
        }
      const hsize_t dims[4] = {hsize_t(g.nz), hsize_t(g.ny), hsize_t(g.nx), 3};
      hid_t sp = H5Screate_simple(4, dims, nullptr);
      hid_t ds = H5Dcreate2(file_, "centres", H5T_IEEE_F32LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      const herr_t st = H5Dwrite(ds, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, xyz.data());
      H5Dclose(ds);
      H5Sclose(sp);
      if (st < 0) {
        H5Fclose(file_);
        file_ = -1;
        throw std::runtime_error("fields.h5: writing the cell centres failed");
      }
    }
  }
  ~FieldWriter() {
    std::lock_guard lk(hdf5_mutex());
    if (file_ >= 0) H5Fclose(file_);
  }
  void write(double t, const vof::VofSolver& s) {
    const auto n = g_.cell.size();
    std::vector<float> a(n, NAN), ux(n, NAN), uy(n, NAN), uz(n, NAN), p(n, NAN), nu(n, NAN);
    for (std::size_t q = 0; q < n; ++q) {
      const int c = g_.cell[q];
      if (c < 0) continue;
      const auto k = std::size_t(c);
      a[q] = float(s.alpha()[k]);
      ux[q] = float(s.velocity()[k].x);
      uy[q] = float(s.velocity()[k].y);
      uz[q] = float(s.velocity()[k].z);
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
    {
      hid_t sp = H5Screate(H5S_SCALAR);
      hid_t a = H5Acreate2(gr, "t", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
      const herr_t st = H5Awrite(a, H5T_NATIVE_DOUBLE, &t);
      H5Aclose(a);
      H5Sclose(sp);
      if (st < 0) {
        H5Gclose(gr);
        throw std::runtime_error("fields.h5: writing a frame's time failed");
      }
    }
    H5Gclose(gr);
    H5Fflush(file_, H5F_SCOPE_LOCAL);  // a checkpoint taken now finds the frame on disk
    times_.push_back(t);
  }
  // fields.xmf: a temporal collection on the cell centres (ORIGIN_DXDY, ORIGIN_DXDYDZ in 3D).
  int finish() {
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
          << " 3\" NumberType=\"Float\" Precision=\"4\" Format=\"HDF\">fields.h5:/centres</DataItem>\n    </Geometry>\n";
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
    return int(times_.size());
  }

 private:
  std::string dir_, work_;
  const LabGrid& g_;
  hid_t file_ = -1;
  std::vector<double> times_;
  bool curvilinear_ = false;
};

// figure.png: material (alpha > 0.5) coloured by speed (blue slow ... red fast), air white.
void write_figure(const std::string& path, const vof::VofSolver& s, const LabGrid& g, double vmax) {
  // Plane set-ups: the x-y section, material coloured by speed. 3D: the plan view (x along, z
  // across), flow depth coloured from blue (thin) to red (the deepest), obstacles grey.
  const int nrow = g.three_d ? g.nz : g.ny;
  const int sc = std::max(1, 600 / std::max(g.nx, 1));
  const int W = g.nx * sc, H = nrow * sc;
  std::vector<unsigned char> rgb[3];
  for (auto& c : rgb) c.assign(std::size_t(W) * H, 255);
  std::vector<double> depth;
  double dmax = 1e-9;
  if (g.three_d) {
    depth.assign(std::size_t(g.nx) * g.nz, -1);
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        double d = 0;
        bool blocked = false;
        for (int j = 0; j < g.ny; ++j) {
          const int c = g.id(i, j, k);
          if (c < 0) blocked = true;
          else d += std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0) * g.dy;
        }
        depth[std::size_t(k) * g.nx + i] = blocked && d < 1e-3 ? -1 : d;  // grey: an obstacle not covered by flow
        dmax = std::max(dmax, d);
      }
  }
  for (int row = 0; row < nrow; ++row)
    for (int i = 0; i < g.nx; ++i) {
      double a = 0, v = 0;
      bool grey = false;
      if (g.three_d) {
        const double d = depth[std::size_t(row) * g.nx + i];
        grey = d < 0;
        a = d > 1e-4 ? 1.0 : 0.0;  // white: dry (below 0.1 mm)
        v = std::max(0.0, d) / dmax;
      } else {
        const int c = g.id(i, row, 0);
        grey = c < 0;
        if (!grey) {
          a = std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0);
          v = std::min(1.0, vof::norm(s.velocity()[std::size_t(c)]) / std::max(vmax, 1e-9));
        }
      }
      const double r = v, gg = 1 - std::abs(2 * v - 1), b = 1 - v;  // blue -> green -> red
      unsigned char col[3] = {static_cast<unsigned char>(255 * (1 - a + a * r)), static_cast<unsigned char>(255 * (1 - a + a * gg)),
                              static_cast<unsigned char>(255 * (1 - a + a * b))};
      if (grey) col[0] = col[1] = col[2] = 128;
      for (int q = 0; q < sc; ++q)
        for (int p = 0; p < sc; ++p) {
          const std::size_t px = std::size_t(H - 1 - (row * sc + q)) * W + i * sc + p;  // y (or z) up
          for (int c = 0; c < 3; ++c) rgb[c][px] = col[c];
        }
    }
  GDALAllRegister();
  auto* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDatasetUniquePtr img(mem->Create("", W, H, 3, GDT_Byte, nullptr));
  for (int c = 0; c < 3; ++c)
    if (img->GetRasterBand(c + 1)->RasterIO(GF_Write, 0, 0, W, H, rgb[c].data(), W, H, GDT_Byte, 0, 0) != CE_None)
      throw std::runtime_error("drawing figure.png failed");
  GDALDatasetUniquePtr out(GetGDALDriverManager()->GetDriverByName("PNG")->CreateCopy(path.c_str(), img.get(), FALSE, nullptr, nullptr, nullptr));
  if (!out) throw std::runtime_error("cannot write " + path);
}

// What a checkpoint must match: the scenario without the end time and the write and checkpoint
// intervals (a run may be continued further than first planned).
std::string lab_state_hash(const ResolvedScenario& r) {
  auto sc = r.scenario;
  sc.mutable_lab()->clear_end_time_s();
  sc.mutable_lab()->clear_write_interval_s();
  sc.mutable_lab()->clear_checkpoint_interval_s();
  std::string json;
  google::protobuf::util::JsonPrintOptions po;
  po.preserve_proto_field_names = true;
  (void)google::protobuf::util::MessageToJsonString(sc, &json, po);
  return sha256_hex(json);
}

// The curved chute of lab.chute (validation.md B8) in channel coordinates (X along the upper chute,
// Y normal to it): the reference curve C(s) by arc length s, straight to the bend, a circular arc
// over it (the inclination changes linearly with s), straight after it; the bed lies b(s, z) above
// it along its normal N(s). point(s, n, z) = C(s) + (b(s, z) + n) N(s) + z e_z.
class ChuteBed {
 public:
  explicit ChuteBed(const v1::Lab& L)
      : s1_(L.chute().bend_start_m()), s2_(L.chute().bend_end_m()), beta_(L.chute().bend_deg() * kPi / 180),
        R_(L.chute().channel_radius_m()), k_(beta_ / (s2_ - s1_)) {}
  vof::Vec point(double s, double n, double z) const {
    double x, y, a;  // the reference point and its tangent's angle to X
    if (s <= s1_) {
      x = s, y = 0, a = 0;
    } else if (s <= s2_) {
      a = k_ * (s - s1_);
      x = s1_ + std::sin(a) / k_, y = (1 - std::cos(a)) / k_;
    } else {
      a = beta_;
      x = s1_ + std::sin(beta_) / k_ + (s - s2_) * std::cos(beta_), y = (1 - std::cos(beta_)) / k_ + (s - s2_) * std::sin(beta_);
    }
    double f = 1;  // the parabola's share: 1 on the chute, smoothly 0 over the bend
    if (s > s1_) {
      const double q = std::clamp((s2_ - s) / (s2_ - s1_), 0.0, 1.0);
      f = q * q * (3 - 2 * q);
    }
    const double h = (R_ > 0 ? z * z / (2 * R_) * f : 0) + n;
    return {x - std::sin(a) * h, y + std::cos(a) * h, z};
  }
  // The reference curve's tangent at s: its angle to X (the tangent is (cos, sin) in X-Y).
  double angle(double s) const { return s <= s1_ ? 0.0 : s <= s2_ ? k_ * (s - s1_) : beta_; }

 private:
  double s1_, s2_, beta_, R_, k_;
};

}  // namespace

RunSummary run_lab(const ResolvedScenario& r, const std::string& out_dir, const RunOptions& opt) {
  // PETSc keeps process-wide state and is not thread-safe: in a server with several workers, VOF
  // runs take turns (depth-averaged runs are not affected).
  static std::mutex petsc_turn;
  std::lock_guard turn(petsc_turn);
  using clk = std::chrono::steady_clock;
  const auto t0 = clk::now();
  const auto& L = r.scenario.lab();
  Material mat = material(L.material());
  if (L.has_phi_deg()) mat.phi_deg = L.phi_deg();
  if (L.has_bed_friction_deg()) mat.delta_deg = L.bed_friction_deg();
  // The block: a plane mesh one cell (dx) thick, or a 3D block with nz cells across the channel.
  LabGrid g;
  g.three_d = L.nz() > 0;
  g.nx = L.nx();
  g.ny = L.ny();
  g.nz = g.three_d ? L.nz() : 1;
  g.x0 = L.x_min();
  g.y0 = L.y_min();
  g.dx = (L.x_max() - L.x_min()) / g.nx;
  g.dy = (L.y_max() - L.y_min()) / g.ny;
  g.z0 = g.three_d ? L.z_min() : 0;
  g.dz = g.three_d ? (L.z_max() - L.z_min()) / g.nz : g.dx;
  g.width = g.three_d ? L.z_max() - L.z_min() : g.dx;
  const double dx = g.dx, dy = g.dy;
  auto blocked = [&L, y0 = g.y0](const vof::Vec& c) {
    for (const auto& o : L.obstacles())
      if (in_obstacle(o, c, y0)) return true;
    return false;
  };
  vof::Mesh m;
  // Bed coordinates of each cell's centre (x along the channel, y above its bed, z across): the
  // mesh's own coordinates for blocks, arc length and height above the bed on a curved chute.
  std::vector<vof::Vec> local;
  try {
    if (L.has_chute()) {
      const ChuteBed bed(L);
      vof::HexGridSpec h;
      h.ni = g.nx, h.nj = g.ny, h.nk = g.nz;
      h.node = [&](int i, int j, int k) { return bed.point(g.x0 + i * g.dx, j * g.dy, g.z0 + k * g.dz); };
      m = vof::structured_hex_mesh(h);
      local.resize(std::size_t(m.cells()));
      for (int k = 0; k < g.nz; ++k)
        for (int j = 0; j < g.ny; ++j)
          for (int i = 0; i < g.nx; ++i)
            local[std::size_t((k * g.ny + j) * g.nx + i)] = {g.x0 + (i + 0.5) * g.dx, (j + 0.5) * g.dy, g.z0 + (k + 0.5) * g.dz};
    } else if (g.three_d) {
      vof::Block3Spec b3;
      b3.x0 = L.x_min(), b3.x1 = L.x_max(), b3.y0 = L.y_min(), b3.y1 = L.y_max(), b3.z0 = L.z_min(), b3.z1 = L.z_max();
      b3.nx = g.nx, b3.ny = g.ny, b3.nz = g.nz;
      b3.blocked = blocked;
      m = vof::block_mesh_3d(b3);
    } else {
      vof::BlockSpec b;
      b.x0 = L.x_min(), b.x1 = L.x_max(), b.y0 = L.y_min(), b.y1 = L.y_max();
      b.nx = g.nx, b.ny = g.ny;
      b.thickness = dx;
      b.blocked_if = blocked;
      m = vof::block_mesh(b);
    }
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(std::string(L.has_chute() ? "lab.chute: " : "lab.obstacles: ") + e.what());
  }
  if (local.empty()) local = m.centre;
  g.cell.assign(std::size_t(g.nx) * g.ny * g.nz, -1);
  for (int c = 0; c < m.cells(); ++c) {
    const auto& p = local[std::size_t(c)];
    const int i = std::clamp(int((p.x - g.x0) / g.dx), 0, g.nx - 1), j = std::clamp(int((p.y - g.y0) / g.dy), 0, g.ny - 1),
              k = g.three_d ? std::clamp(int((p.z - g.z0) / g.dz), 0, g.nz - 1) : 0;
    g.cell[g.at(i, j, k)] = c;
  }
  g.kc = g.three_d ? std::clamp(int((0.5 * (L.z_min() + L.z_max()) - g.z0) / g.dz), 0, g.nz - 1) : 0;
  vof::VofConfig c;
  c.rho1 = mat.rho;
  c.phi_deg = mat.phi_deg;
  c.max_co = c.max_alpha_co = L.max_courant();
  c.n_correctors = L.correctors();
  c.n_outer_correctors = L.has_outer_correctors() ? L.outer_correctors() : 1;
  c.viscous_transpose = L.viscous_transpose() == "off"        ? vof::Transpose::off
                        : L.viscous_transpose() == "explicit" ? vof::Transpose::linear
                                                              : vof::Transpose::harmonic;  // the default
  c.momentum_convection = L.momentum_convection() == "limited_linear" ? vof::Convection::limited_linear : vof::Convection::upwind;
  c.coulomb_pressure = L.coulomb_pressure() == "excess" ? vof::CoulombPressure::excess : vof::CoulombPressure::total;
  c.wall_viscosity = L.wall_viscosity() == "cell" ? vof::WallViscosity::cell : vof::WallViscosity::face;
  if (!L.pressure_preconditioner().empty()) c.pressure_pc = L.pressure_preconditioner();
  c.active_layers = L.active_layers() < 0 ? 0 : L.active_layers();
  c.consistent = c.momentum_predictor = L.pressure_coupling() == "consistent";
  const double zeta = L.inclination_deg() * kPi / 180;
  const double omega = L.rotation_period_s() > 0 ? 2 * kPi / L.rotation_period_s() : 0.0;
  c.gravity = [zeta, omega](double t) {
    // In the frame of a channel turning at omega (counter-clockwise), gravity turns clockwise.
    const double a = zeta + omega * t;
    return vof::Vec{9.81 * std::sin(a), -9.81 * std::cos(a), 0};
  };
  // Conditions: listed parts of sides become their own patches; the rest stays wall.
  for (const char* side : {"bottom", "top", "left", "right", "back", "front", "obstacle"})
    if (m.patch_index(side) >= 0) c.bc[side].kind = vof::Bc::wall;
  for (int k = 0; k < L.boundaries_size(); ++k) {
    const auto& lb = L.boundaries(k);
    const std::string name = lb.side() + "-" + std::to_string(k);
    const bool along_x = lb.side() != "left" && lb.side() != "right";
    const double from = lb.has_from() ? lb.from() : -1e300, to = lb.has_to() ? lb.to() : 1e300;
    if (m.patch_index(lb.side()) < 0) throw ScenarioError("lab.boundaries[" + std::to_string(k) + "]: side " + lb.side() + " is already taken");
    vof::split_patch(m, lb.side(), name, [&](const vof::Vec& cf) {
      const double u = along_x ? cf.x : cf.y;
      return u >= from && u <= to;
    });
    if (m.patch_index(name) < 0) throw ScenarioError("lab.boundaries[" + std::to_string(k) + "]: no face of side " + lb.side() + " lies in [from, to]");
    vof::PatchBc pb;
    pb.kind = lb.kind() == "atmosphere" ? vof::Bc::atmosphere
              : lb.kind() == "outflow"  ? vof::Bc::outflow
              : lb.kind() == "coulomb-slip" ? vof::Bc::coulomb_slip
              : lb.kind() == "coulomb-friction" ? vof::Bc::coulomb_friction
              : lb.kind() == "inflow"   ? vof::Bc::inflow
              : lb.kind() == "symmetry" ? vof::Bc::symmetry
                                        : vof::Bc::wall;
    if (pb.kind == vof::Bc::inflow) {
      const double u0 = lb.inflow_u0(), dudy = lb.inflow_dudy(), hin = lb.inflow_height(), ybase = L.y_min();
      // Material below the fill height with the profile; air above enters at rest (appendix A.4:
      // "else (0, 0)").
      pb.inflow_velocity = [=](const vof::Vec& cf) { return cf.y - ybase < hin ? vof::Vec{u0 + dudy * (cf.y - ybase), 0, 0} : vof::Vec{}; };
      pb.inflow_alpha = [=](const vof::Vec& cf) { return cf.y - ybase < hin ? 1.0 : 0.0; };
    }
    pb.tan_delta = std::tan(mat.delta_deg * kPi / 180);
    c.bc[name] = pb;
  }
  for (auto it = c.bc.begin(); it != c.bc.end();)  // sides wholly taken by listed parts
    it = m.patch_index(it->first) < 0 ? c.bc.erase(it) : std::next(it);
  vof::VofSolver s(m, c);
  std::vector<double> alpha(std::size_t(m.cells()), 0.0);
  auto inside = [](const v1::LabRegion& f, const vof::Vec& p) {
    if (f.cap_radius() > 0) {  // a spherical cap on the bed
      const double r = f.cap_radius(), q = r * r - (p.x - f.cap_x()) * (p.x - f.cap_x()) - (p.z - f.cap_z()) * (p.z - f.cap_z());
      return q > 0 && p.y < std::sqrt(q) - (r - f.cap_height());
    }
    if (f.polygon_xy_size() == 0) return p.x >= f.x_min() && p.x <= f.x_max() && p.y >= f.y_min() && p.y <= f.y_max();
    return in_polygon(f.polygon_xy(), p.x, p.y);
  };
  bool has_inflow = false;
  for (const auto& lb : L.boundaries()) has_inflow |= lb.kind() == "inflow";
  // Cells cut by a fill's outline get the share of their cell inside it, sampled on 4 x 4 (x 4 in
  // 3D) points: a stair-stepped surface is locally steeper than phi at every step, and its corner
  // cells fail at once (on the static B9 heap at 2.5 mm one reached 0.12 m/s).
  const int ns = 4;
  const int nsz = g.three_d ? ns : 1;
  for (int k = 0; k < m.cells(); ++k) {
    const vof::Vec& c = local[std::size_t(k)];
    int in = 0;
    for (int a = 0; a < ns; ++a)
      for (int b = 0; b < ns; ++b)
        for (int e = 0; e < nsz; ++e) {
          const vof::Vec q{c.x + ((a + 0.5) / ns - 0.5) * g.dx, c.y + ((b + 0.5) / ns - 0.5) * g.dy,
                           g.three_d ? c.z + ((e + 0.5) / nsz - 0.5) * g.dz : c.z};
          for (const auto& f : L.fill())
            if (inside(f, q)) {
              ++in;
              break;
            }
        }
    alpha[std::size_t(k)] = double(in) / (ns * ns * nsz);
  }
  double v0 = 0;
  for (int k = 0; k < m.cells(); ++k) v0 += alpha[std::size_t(k)] * m.volume[std::size_t(k)];
  if (v0 <= 0 && !has_inflow) throw ScenarioError("lab.fill: no cell has material from the fill regions (and no inflow feeds the channel)");
  const std::string state_hash = lab_state_hash(r);
  LabCheckpoint restart;
  if (!opt.restart_path.empty()) {
    restart = read_checkpoint(opt.restart_path);
    if (restart.scenario_hash != state_hash)
      throw ScenarioError("checkpoint " + opt.restart_path + " belongs to another scenario (only end_time_s, write_interval_s and "
                          "checkpoint_interval_s may differ)");
    if (!(restart.state.t < L.end_time_s()))
      throw ScenarioError("checkpoint " + opt.restart_path + " is at t = " + json_number(restart.state.t) + " s, not before lab.end_time_s");
    try {
      s.restore(restart.state);
    } catch (const vof::VofError& e) {
      throw ScenarioError("checkpoint " + opt.restart_path + ": " + e.what());
    }
  } else {
    s.initialise(alpha);
  }

  RunSummary sum;
  sum.nx = g.nx;
  sum.ny = g.ny * g.nz;
  sum.dx = dx;
  sum.crs = "channel coordinates";
  sum.release_volume_m3 = v0;
  sum.volume_initial = v0;
  sum.seconds_prepare = std::chrono::duration<double>(clk::now() - t0).count();
  // With checkpoints the frames are written next to the checkpoint (CHECKPOINT.fields.h5), so that
  // a continued run carries on with them; a run continued from RESTART takes RESTART.fields.h5's
  // frames up to its time.
  FieldWriter fields(out_dir, g, L.has_chute() ? &m.centre : nullptr,
                     opt.checkpoint_path.empty() ? std::string() : opt.checkpoint_path + ".fields.h5",
                     opt.restart_path.empty() ? std::string() : opt.restart_path + ".fields.h5", restart.state.t);
  double next_write = L.write_interval_s() > 0 ? L.write_interval_s() : 1e300;
  double peak = 0, t_peak = 0, t_rest = -1, pressure_s = 0, pressure_solve_s = 0, alpha_min = 1, alpha_max = 0, div = 0, last_speed = 0;
  long steps = 0, p_its = 0;
  double active_sum = 0;
  int active_max = 0;
  // The running figures a checkpoint carries.
  auto figures = [&] {
    return std::map<std::string, double>{{"peak", peak},       {"t_peak", t_peak},         {"t_rest", t_rest},
                                         {"pressure_s", pressure_s}, {"pressure_solve_s", pressure_solve_s},
                                         {"alpha_min", alpha_min}, {"alpha_max", alpha_max},
                                         {"div", div},         {"last_speed", last_speed}, {"p_its", double(p_its)},
                                         {"active_sum", active_sum}, {"active_max", double(active_max)}};
  };
  if (!opt.restart_path.empty()) {
    auto f = [&](const char* k) {
      const auto it = restart.figures.find(k);
      if (it == restart.figures.end()) throw ScenarioError("checkpoint " + opt.restart_path + ": damaged (no figure '" + k + "')");
      return it->second;
    };
    peak = f("peak"), t_peak = f("t_peak"), t_rest = f("t_rest"), pressure_s = f("pressure_s"), alpha_min = f("alpha_min");
    alpha_max = f("alpha_max"), div = f("div"), last_speed = f("last_speed"), p_its = long(f("p_its")), active_sum = f("active_sum");
    active_max = int(f("active_max"));
    // A timing only, and absent from checkpoints written before it was carried.
    const auto ps = restart.figures.find("pressure_solve_s");
    pressure_solve_s = ps == restart.figures.end() ? 0.0 : ps->second;
    steps = restart.steps;
    if (L.write_interval_s() > 0)  // the next regular frame after the checkpoint
      next_write = L.write_interval_s() * (std::floor(restart.state.t / L.write_interval_s() + 1e-9) + 1);
  } else {
    fields.write(0, s);
  }
  // Monitors sampled along the run (validation.md B3): granular outflow through the right end (in
  // litres per second for the laboratory's 10 cm wide channel), the strain rate du/dy at the gate
  // (x = 0: the least-squares slope of u over the material cells of the column just downstream),
  // and the share of the material (alpha > 0.5) moving faster than 1 cm/s.
  std::vector<int> right_faces;
  for (const auto& p : m.patches)
    if (p.name.rfind("right", 0) == 0)
      for (int f = p.start; f < p.start + p.size; ++f) right_faces.push_back(f);
  const int gate_i = (0 > L.x_min() && 0 < L.x_max()) ? std::clamp(int((0 - g.x0) / dx + 1e-9), 0, g.nx - 1) : -1;
  const double mon_every = std::min(0.01, L.end_time_s() / 50);
  double next_mon = s.time() + mon_every;
  std::vector<int> gate_faces;  // internal faces on the line x = 0, normal along x
  for (int f = 0; f < m.n_internal; ++f)
    if (std::abs(m.Cf[std::size_t(f)].x) < 0.25 * dx && std::abs(m.Sf[std::size_t(f)].x) > 0.5 * m.magSf[std::size_t(f)])
      gate_faces.push_back(f);
  std::vector<double> mon_t, mon_q, mon_gate, mon_sr, mon_moving, mon_shock;
  double t_fluid = -1;
  // The shock at a closed end (validation.md B6: inflow and a wall at the right end): the bore,
  // i.e. the upstream edge of the columns, from the end wall upstream, that hold at least two cells'
  // depth of material and whose depth-averaged speed is below half the inflow's mean speed (at least
  // 5 cm/s). (Not the
  // edge of the resting deposit: under sand's bore the deposit keeps creeping for a while, and that
  // edge stalls and jumps while the bore runs at a constant speed; validation.md B6.)
  bool end_wall = has_inflow;
  for (const auto& lb : L.boundaries()) end_wall &= lb.side() != "right";
  double inflow_speed = 0;
  for (const auto& lb : L.boundaries())
    if (lb.kind() == "inflow") inflow_speed = std::max(inflow_speed, lb.inflow_u0() + 0.5 * lb.inflow_dudy() * lb.inflow_height());
  auto shock_x = [&] {
    int i = g.nx - 1;
    for (; i >= 0; --i) {
      double depth = 0, flux = 0;
      for (int jj = 0; jj < g.ny; ++jj)
        if (const int c2 = g.id(i, jj, g.kc); c2 >= 0) {
          const double a = std::clamp(s.alpha()[std::size_t(c2)], 0.0, 1.0) * dy;
          depth += a;
          flux += a * vof::norm(s.velocity()[std::size_t(c2)]);
        }
      if (depth < 2 * dy || flux >= std::max(0.5 * inflow_speed, 0.05) * depth) break;  // at least 5 cm/s
    }
    return i < g.nx - 1 ? g.x0 + (i + 1) * dx : NAN;
  };
  // The rotating box (validation.md B1): the free surface's angle to the horizontal (perpendicular
  // to gravity) in the central region (within 5 cm of the box centre), from the principal axis of
  // the points where alpha crosses 0.5 between neighbouring cells.
  const bool rotating = L.rotation_period_s() > 0 && !g.three_d;
  std::vector<double> mon_surface;
  const vof::Vec box_centre{0.5 * (L.x_min() + L.x_max()), 0.5 * (L.y_min() + L.y_max()), 0};
  auto surface_angle = [&](double t) {
    double n = 0, mx = 0, my = 0, sxx = 0, sxy = 0, syy = 0;
    for (int f = 0; f < m.n_internal; ++f) {
      const int o = m.owner[std::size_t(f)], nb = m.neighbour[std::size_t(f)];
      const double ao = s.alpha()[std::size_t(o)], an = s.alpha()[std::size_t(nb)];
      if ((ao - 0.5) * (an - 0.5) >= 0) continue;
      const double w = (0.5 - ao) / (an - ao);
      const vof::Vec& po = m.centre[std::size_t(o)];
      const vof::Vec& pn = m.centre[std::size_t(nb)];
      const double x = po.x + w * (pn.x - po.x), y = po.y + w * (pn.y - po.y);
      if (std::hypot(x - box_centre.x, y - box_centre.y) > 0.05) continue;
      n += 1, mx += x, my += y, sxx += x * x, sxy += x * y, syy += y * y;
    }
    if (n < 3) return double(NAN);
    mx /= n, my /= n;
    const double cxx = sxx / n - mx * mx, cxy = sxy / n - mx * my, cyy = syy / n - my * my;
    const double dir = 0.5 * std::atan2(2 * cxy, cxx - cyy);  // the principal axis
    const vof::Vec gv = c.gravity(t);
    const double horizontal = std::atan2(gv.y, gv.x) + 0.5 * kPi;
    double d = std::fmod(std::abs(dir - horizontal), kPi);
    if (d > 0.5 * kPi) d = kPi - d;
    return d * 180 / kPi;
  };
  auto monitor = [&](double t) {
    if (rotating) mon_surface.push_back(surface_angle(t));
    double q = 0;
    for (int f : right_faces) q += s.granular_flux()[std::size_t(f)];
    const double per_width = g.three_d ? 1.0 : 0.1 / g.width;  // plane: as in the 10 cm channel; 3D: the modelled width
    mon_q.push_back(1000 * q * per_width);
    double qg = 0;
    for (int f : gate_faces) qg += (m.Sf[std::size_t(f)].x > 0 ? 1 : -1) * s.granular_flux()[std::size_t(f)];
    mon_gate.push_back(gate_faces.empty() ? NAN : 1000 * qg * per_width);
    double sr = NAN;
    if (gate_i >= 0) {
      double sy = 0, su = 0, syy = 0, syu = 0, n = 0;
      for (int jj = 0; jj < g.ny; ++jj) {
        const int cc = g.id(gate_i, jj, g.kc);
        if (cc < 0) continue;
        const auto k = std::size_t(cc);
        if (s.alpha()[k] <= 0.5) continue;
        const double y = g.y0 + (jj + 0.5) * dy, u = s.velocity()[k].x;
        sy += y, su += u, syy += y * y, syu += y * u, n += 1;
      }
      if (n >= 3) sr = (n * syu - sy * su) / (n * syy - sy * sy);
    }
    mon_sr.push_back(sr);
    double mat = 0, moving = 0;
    for (int k = 0; k < m.cells(); ++k)
      if (s.alpha()[std::size_t(k)] > 0.5) {
        mat += 1;
        if (vof::norm(s.velocity()[std::size_t(k)]) > 0.01) moving += 1;
      }
    mon_moving.push_back(mat > 0 ? moving / mat : NAN);
    if (end_wall) mon_shock.push_back(shock_x());
    if (t_fluid < 0 && mat > 0 && moving >= 0.99 * mat) t_fluid = t;
    mon_t.push_back(t);
  };
  const bool checkpoints = !opt.checkpoint_path.empty();
  const double cp_every = L.checkpoint_interval_s() > 0      ? L.checkpoint_interval_s()
                          : opt.checkpoint_interval_s > 0 ? opt.checkpoint_interval_s
                                                          : 1e300;
  double next_cp = cp_every < 1e300 ? cp_every * (std::floor(s.time() / cp_every + 1e-9) + 1) : 1e300;
  // The monitors so far travel with the checkpoint, so that a continued run's run.json is the
  // uninterrupted run's.
  auto series_refs = [&] {
    return std::vector<std::pair<const char*, std::vector<double>*>>{{"t", &mon_t},           {"outflow", &mon_q},
                                                                     {"gate_flux", &mon_gate}, {"gate_strain_rate", &mon_sr},
                                                                     {"moving_share", &mon_moving}, {"shock", &mon_shock},
                                                                     {"surface_angle", &mon_surface}};
  };
  if (!opt.restart_path.empty()) {
    for (auto [name, v] : series_refs()) {
      const auto it = restart.series.find(name);
      if (it == restart.series.end()) throw ScenarioError("checkpoint " + opt.restart_path + ": damaged (no series '" + name + "')");
      *v = it->second;
    }
    const auto tf = restart.figures.find("t_fluid"), nm = restart.figures.find("next_mon");
    if (tf == restart.figures.end() || nm == restart.figures.end())
      throw ScenarioError("checkpoint " + opt.restart_path + ": damaged (no monitor times)");
    t_fluid = tf->second;
    next_mon = nm->second;
  }
  auto write_cp = [&] {
    LabCheckpoint cp;
    cp.scenario_hash = state_hash;
    cp.steps = steps;
    cp.figures = figures();
    cp.figures["t_fluid"] = t_fluid;
    cp.figures["next_mon"] = next_mon;
    for (auto [name, v] : series_refs()) cp.series[name] = *v;
    cp.state = s.state();
    write_checkpoint(opt.checkpoint_path, cp);
  };
  bool cancelled = false;
  const auto t1 = clk::now();
  s.run(L.end_time_s(), [&](const vof::StepStats& st) {
    ++steps;
    p_its += st.pressure_iterations;
    active_sum += st.active_cells;
    active_max = std::max(active_max, st.active_cells);
    pressure_s += st.seconds_pressure;
    pressure_solve_s += st.seconds_pressure_solve;
    alpha_min = std::min(alpha_min, st.alpha_min);
    alpha_max = std::max(alpha_max, st.alpha_max);
    div = std::max(div, st.divergence);
    last_speed = st.max_speed;
    if (st.max_speed > peak) {
      peak = st.max_speed;
      t_peak = st.t;
    }
    if (st.max_speed >= 0.01) t_rest = -1;
    else if (t_rest < 0 && peak >= 0.01) t_rest = st.t;
    if (st.t >= next_write - 1e-12) {
      fields.write(st.t, s);
      next_write += L.write_interval_s();
    }
    if (st.t >= next_mon - 1e-12) {
      monitor(st.t);
      next_mon += mon_every;
    }
    if (checkpoints && st.t >= next_cp - 1e-12 && st.t < L.end_time_s() - 1e-12) {
      write_cp();
      next_cp += cp_every;
    }
    if (opt.progress && steps % std::max(1L, opt.progress_every) == 0) {
      engine::Progress p;
      p.t = st.t;
      p.dt = st.dt;
      p.mass = st.granular_volume;
      p.max_speed = st.max_speed;
      p.active_fraction = double(st.active_cells) / m.cells();
      p.step = steps;
      if (!opt.progress(p) && st.t < L.end_time_s() - 1e-12) {  // on the last step the run is done anyway
        cancelled = true;
        if (checkpoints) write_cp();  // the run can continue from here
        return false;
      }
    }
    return true;
  });
  sum.seconds_run = std::chrono::duration<double>(clk::now() - t1).count();
  sum.steps = steps;
  sum.t = s.time();
  sum.stop = cancelled ? "cancelled" : "end-time";
  if (cancelled) return sum;
  const auto t2 = clk::now();
  // Deposit figures from the column heights.
  // Column heights (in 3D averaged across the width).
  std::vector<double> h(std::size_t(g.nx), 0.0);
  double v1 = 0;
  for (int k = 0; k < m.cells(); ++k) {
    const auto& p = local[std::size_t(k)];  // bed coordinates (on a curved chute: arc length)
    h[std::size_t(std::clamp(int((p.x - g.x0) / dx), 0, g.nx - 1))] += s.alpha()[std::size_t(k)] * dy * g.dz / g.width;
    v1 += s.alpha()[std::size_t(k)] * m.volume[std::size_t(k)];
  }
  double front = g.x0, hmax = 0;
  for (int i = 0; i < g.nx; ++i) {
    if (h[std::size_t(i)] >= 0.5 * dy) front = g.x0 + (i + 1) * dx;  // at least half a cell of material
    hmax = std::max(hmax, h[std::size_t(i)]);
  }
  // Surface angles right of the highest column: the upper surface (least-squares slope of the
  // column heights between 90 % and 50 % of the highest) and the mean slope from 80 % to 20 %.
  int imax = int(std::max_element(h.begin(), h.end()) - h.begin());
  while (imax + 1 < g.nx && h[std::size_t(imax) + 1] >= 0.999 * hmax) ++imax;  // the plateau's right end
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (int i = imax; i < g.nx; ++i)
    if (h[std::size_t(i)] < 0.9 * hmax && h[std::size_t(i)] > 0.5 * hmax) {
      const double xx = g.x0 + (i + 0.5) * dx;
      sx += xx, sy += h[std::size_t(i)], sxx += xx * xx, sxy += xx * h[std::size_t(i)], n += 1;
    }
  const double upper = n >= 2 ? std::atan(-(n * sxy - sx * sy) / (n * sxx - sx * sx)) * 180 / kPi : NAN;
  double xh = NAN, xl = NAN;
  for (int i = imax; i < g.nx; ++i) {
    if (std::isnan(xh) && h[std::size_t(i)] < 0.8 * hmax) xh = g.x0 + (i + 0.5) * dx;
    if (std::isnan(xl) && h[std::size_t(i)] < 0.2 * hmax) xl = g.x0 + (i + 0.5) * dx;
  }
  const double angle = (std::isnan(xh) || std::isnan(xl) || xl <= xh) ? NAN : std::atan(0.6 * hmax / (xl - xh)) * 180 / kPi;
  sum.volume_final = v1;
  sum.volume_error = has_inflow ? NAN : std::abs(v1 - v0) / v0;  // material comes in: no conservation figure
  sum.max_speed = peak;
  sum.runout_m = front;
  sum.max_depth = hmax;
  const int frames = fields.finish();
  write_figure(out_dir + "/figure.png", s, g, std::max(peak, 0.01));
  // 3D (validation.md B7): the flow depth map at the end; the undisturbed depth (median over the
  // wetted columns of the first quarter of the chute), the deepest column and its ratio to it, and
  // per obstacle the dry area (depth below 1 mm) in its shadow: up to 15 cm downstream of its
  // centre, as wide as the obstacle.
  std::ostringstream chute;
  // comparison.png's title (the section of a plane run, the plan view of a 3D one).
  // The cell size is stated because a scenario's name may describe its file's resolution while the
  // run took another (the benchmarks' full variants).
  std::ostringstream cells_mm;
  cells_mm << std::setprecision(3) << dx * 1e3 << " x " << dy * 1e3;
  if (g.three_d) cells_mm << " x " << g.dz * 1e3;
  const std::string figure_title = (r.scenario.name().empty() ? std::string("laboratory run") : r.scenario.name()) + ", t = " + json_number(s.time()) +
                                   " s, cells " + cells_mm.str() + " mm";
  figures::PlanFigure plan;  // comparison.png of a 3D run
  const ChuteBed chute_bed(L);  // used on a curved chute only
  if (g.three_d) {
    std::vector<double> d(std::size_t(g.nx) * g.nz, 0.0), upstream;
    std::vector<char> blocked_col(d.size(), 0);
    plan.ux.assign(d.size(), 0.0);
    plan.uz.assign(d.size(), 0.0);
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i)
        for (int j = 0; j < g.ny; ++j) {
          const int c = g.id(i, j, k);
          const std::size_t col = std::size_t(k) * g.nx + i;
          if (c < 0) {
            blocked_col[col] = 1;
            continue;
          }
          const double a = std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0) * dy;
          const auto& u = s.velocity()[std::size_t(c)];
          d[col] += a;
          // Along the bed: on a curved chute along the reference curve's tangent at the cell.
          const double ta = L.has_chute() ? chute_bed.angle(local[std::size_t(c)].x) : 0.0;
          plan.ux[col] += a * (u.x * std::cos(ta) + u.y * std::sin(ta));
          plan.uz[col] += a * u.z;
        }
    plan.depth.resize(d.size());
    for (std::size_t col = 0; col < d.size(); ++col) {
      if (d[col] > 0) plan.ux[col] /= d[col], plan.uz[col] /= d[col];
      plan.depth[col] = blocked_col[col] && d[col] < 1e-3 ? NAN : d[col];  // grey: an obstacle not covered by flow
    }
    double dmax = 0, xm = NAN, zm = NAN;
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        const double v = d[std::size_t(k) * g.nx + i];
        if (i < g.nx / 4 && v > 0.5 * dy && !blocked_col[std::size_t(k) * g.nx + i]) upstream.push_back(v);
        if (v > dmax) dmax = v, xm = g.x0 + (i + 0.5) * dx, zm = g.z0 + (k + 0.5) * g.dz;
      }
    std::sort(upstream.begin(), upstream.end());
    const double und = upstream.empty() ? NAN : upstream[upstream.size() / 2];
    plan.title = figure_title;
    plan.nx = g.nx, plan.nz = g.nz, plan.x0 = g.x0, plan.z0 = g.z0, plan.dx = dx, plan.dz = g.dz;
    if (L.has_chute()) plan.xlabel = "arc length [m]";
    plan.undisturbed = und, plan.deepest = dmax, plan.deepest_x = xm, plan.deepest_z = zm;
    if (L.has_reference()) {
      plan.ref_source = L.reference().source();
      if (L.reference().has_depth_ratio_max()) plan.ref_depth_ratio = L.reference().depth_ratio_max();
    }
    chute << "  \"chute\": {\"undisturbed_depth_m\": " << json_number(und) << ", \"max_depth_m\": " << json_number(dmax) << ", \"max_depth_x_m\": " << json_number(xm)
          << ", \"max_depth_z_m\": " << json_number(zm) << ", \"max_depth_ratio\": " << json_number(und > 0 ? dmax / und : NAN) << ", \"obstacles\": [";
    for (int q = 0; q < L.obstacles_size(); ++q) {
      const auto& o = L.obstacles(q);
      // The window: from the centre (a polygon across the width: from its downstream end) 15 cm
      // downstream, as wide as the obstacle (a polygon: the whole width).
      const bool poly = o.shape() == "polygon";
      double wx0 = o.x(), wz0 = o.z() - 0.5 * o.edge(), wz1 = o.z() + 0.5 * o.edge();
      if (o.shape() == "cylinder") wz0 = o.z() - o.radius(), wz1 = o.z() + o.radius();
      if (poly) {
        wx0 = -1e300, wz0 = g.z0, wz1 = g.z0 + g.width;
        for (int q2 = 0; q2 + 1 < o.polygon_xy_size(); q2 += 2) wx0 = std::max(wx0, o.polygon_xy(q2));
      }
      const double wx1 = wx0 + 0.15;
      double dry = 0;
      for (int k = 0; k < g.nz; ++k)
        for (int i = 0; i < g.nx; ++i) {
          const double x = g.x0 + (i + 0.5) * dx, z = g.z0 + (k + 0.5) * g.dz;
          if (x > wx0 && x < wx1 && z > wz0 && z < wz1 && !blocked_col[std::size_t(k) * g.nx + i] && d[std::size_t(k) * g.nx + i] < 1e-3)
            dry += dx * g.dz;
        }
      chute << (q ? ", " : "") << "{\"shape\": \"" << o.shape() << "\", \"sheltered_dry_area_m2\": " << json_number(dry) << "}";
      plan.shadows.push_back({o.shape() == "cylinder" ? "cylinder" : o.shape() == "tetrahedron-edge" ? "tetrahedron (edge upstream)"
                              : o.shape() == "tetrahedron-face" ? "tetrahedron (face upstream)" : o.shape(),
                              wx0, wx1, wz0, wz1, dry});
    }
    chute << "]},\n";
    // The curved chute (validation.md B8): where the deposit lies along the arc length (on the
    // chute, in the bend, on the run-out), its extent, its half-width on the chute and on the
    // run-out (z from lab.z_min, the symmetry plane of a half chute), its highest point and centroid.
    if (L.has_chute()) {
      const double s1 = L.chute().bend_start_m(), s2 = L.chute().bend_end_m();
      double vol[3] = {0, 0, 0}, sm = 0, mv = 0, smin = NAN, smax = NAN, w_chute = 0, w_run = 0;
      for (int c = 0; c < m.cells(); ++c) {
        const double v = std::clamp(s.alpha()[std::size_t(c)], 0.0, 1.0) * m.volume[std::size_t(c)], x = local[std::size_t(c)].x;
        vol[x < s1 ? 0 : x <= s2 ? 1 : 2] += v;
        sm += v * x, mv += v;
      }
      for (int k = 0; k < g.nz; ++k)
        for (int i = 0; i < g.nx; ++i) {
          if (d[std::size_t(k) * g.nx + i] < 1e-3) continue;
          const double x = g.x0 + (i + 0.5) * dx, z = std::abs(g.z0 + (k + 1) * g.dz - L.z_min());
          smin = std::isnan(smin) ? x : std::min(smin, x), smax = std::isnan(smax) ? x : std::max(smax, x);
          if (x < s1) w_chute = std::max(w_chute, z);
          if (x > s2) w_run = std::max(w_run, z);
        }
      const double tot = std::max(mv, 1e-300);
      chute << "  \"curved_chute\": {\"share_on_chute\": " << json_number(vol[0] / tot) << ", \"share_in_bend\": " << json_number(vol[1] / tot)
            << ", \"share_on_runout\": " << json_number(vol[2] / tot) << ", \"deposit_from_m\": " << json_number(smin)
            << ", \"deposit_to_m\": " << json_number(smax) << ", \"half_width_on_chute_m\": " << json_number(w_chute)
            << ", \"half_width_on_runout_m\": " << json_number(w_run) << ", \"highest_x_m\": " << json_number(xm)
            << ", \"highest_z_m\": " << json_number(zm) << ", \"highest_depth_m\": " << json_number(dmax)
            << ", \"centroid_x_m\": " << json_number(sm / tot) << "},\n";
    }
  }
  sum.files = {"fields.h5", "fields.xmf", "figure.png", "run.json"};
  sum.seconds_write = std::chrono::duration<double>(clk::now() - t2).count();

  std::string scen;
  google::protobuf::util::JsonPrintOptions po;
  po.preserve_proto_field_names = true;
  (void)google::protobuf::util::MessageToJsonString(r.scenario, &scen, po);
  std::ofstream j(out_dir + "/run.json");
  j << "{\n  \"software\": {\"name\": \"runout\", \"version\": \"" << RUNOUT_VERSION << "\"},\n";
  j << "  \"engine\": \"vof\",\n  \"scenario\": " << scen << ",\n";
  j << "  \"mesh\": {\"cells\": " << m.cells() << ", \"nx\": " << g.nx << ", \"ny\": " << g.ny << ", \"nz\": " << (g.three_d ? g.nz : 0)
    << ", \"dx_m\": " << json_number(dx) << ", \"dy_m\": " << json_number(dy) << ", \"dz_m\": " << json_number(g.three_d ? g.dz : NAN) << "},\n";
  j << "  \"solver\": {\"steps\": " << steps << ", \"simulated_s\": " << json_number(s.time()) << ", \"pressure_iterations\": " << p_its
    << ", \"alpha_min\": " << json_number(alpha_min) << ", \"alpha_max\": " << json_number(alpha_max) << ", \"max_divergence_1_s\": " << json_number(div)
    << ", \"active_cells_mean\": " << json_number(steps ? active_sum / steps : NAN) << ", \"active_cells_max\": " << active_max
    << ", \"stop\": \"" << sum.stop << "\", \"continued_from_t_s\": " << json_number(opt.restart_path.empty() ? NAN : restart.state.t)
    << "},\n";
  j << "  \"results\": {\"peak_speed_m_s\": " << json_number(peak) << ", \"peak_speed_time_s\": " << json_number(t_peak)
    << ", \"rest_time_s\": " << json_number(t_rest >= 0 ? t_rest : NAN) << ", \"final_speed_m_s\": " << json_number(last_speed)
    << ", \"front_x_m\": " << json_number(front) << ", \"deposit_height_m\": " << json_number(hmax) << ", \"upper_surface_angle_deg\": " << json_number(upper) << ", \"mean_surface_angle_deg\": " << json_number(angle)
    << ", \"volume_initial_m3\": " << json_number(v0) << ", \"volume_final_m3\": " << json_number(v1) << ", \"volume_relative_error\": " << json_number(sum.volume_error)
    << ", \"frames\": " << frames << "},\n";
  // Stations (centre line in 3D): depth, depth-averaged, surface and basal velocity along x, the
  // basal speed (the slip velocity along the bed, a ramp included), the strain rate du/dy (least
  // squares over the material cells) and the profile. Cells blocked by an obstacle are skipped: on a
  // ramp the column starts at the ramp's surface.
  j << "  \"stations\": [";
  for (int q = 0; q < L.stations_x_size(); ++q) {
    const double xs = L.stations_x(q);
    const int i = std::clamp(int((xs - g.x0) / dx), 0, g.nx - 1);
    double depth = 0, flux = 0, surface = NAN, basal = NAN, basal_speed = NAN, bed = NAN;
    double sy = 0, su = 0, syy = 0, syu = 0, nn = 0;
    std::ostringstream prof;
    bool first = true;
    for (int jj = 0; jj < g.ny; ++jj) {
      const int c = g.id(i, jj, g.kc);
      if (c < 0) continue;
      const auto k = std::size_t(c);
      const double y = g.y0 + (jj + 0.5) * dy;
      if (std::isnan(bed)) bed = y - 0.5 * dy;
      const double a = std::clamp(s.alpha()[k], 0.0, 1.0), u = s.velocity()[k].x;
      depth += a * dy;
      flux += a * u * dy;
      if (a > 0.5) {
        if (std::isnan(basal)) basal = u, basal_speed = vof::norm(s.velocity()[k]);
        surface = u;
        sy += y, su += u, syy += y * y, syu += y * u, nn += 1;
      }
      prof << (first ? "" : ", ") << "[" << json_number(y) << ", " << json_number(a) << ", " << json_number(u) << "]";
      first = false;
    }
    const double strain = nn >= 3 ? (nn * syu - sy * su) / (nn * syy - sy * sy) : NAN;
    j << (q ? ", " : "") << "\n    {\"x_m\": " << json_number(xs) << ", \"bed_y_m\": " << json_number(bed) << ", \"depth_m\": " << json_number(depth)
      << ", \"depth_averaged_u_m_s\": " << json_number(depth > 0 ? flux / depth : NAN) << ", \"surface_u_m_s\": " << json_number(surface)
      << ", \"basal_u_m_s\": " << json_number(basal) << ", \"basal_speed_m_s\": " << json_number(basal_speed) << ", \"strain_rate_1_s\": " << json_number(strain)
      << ", \"profile_y_alpha_u\": [" << prof.str() << "]}";
  }
  j << "],\n";
  // The median of a monitor's finite samples between two times.
  auto median_between = [&](const std::vector<double>& v, double a, double b) {
    std::vector<double> w;
    for (std::size_t q = 0; q < mon_t.size() && q < v.size(); ++q)
      if (mon_t[q] >= a && mon_t[q] <= b && std::isfinite(v[q])) w.push_back(v[q]);
    if (w.empty()) return double(NAN);
    std::nth_element(w.begin(), w.begin() + long(w.size() / 2), w.end());
    return w[w.size() / 2];
  };
  {
    // The outflow's plateau: the median over the second half of the run.
    const double plateau = median_between(mon_q, 0.5 * L.end_time_s(), 1e300);
    const double plateau_gate = median_between(mon_gate, 0.5 * L.end_time_s(), 1e300);
    auto series = [&](const std::vector<double>& v) {
      std::ostringstream o;
      for (std::size_t q = 0; q < v.size(); ++q) o << (q ? ", " : "") << json_number(v[q]);
      return o.str();
    };
    j << "  \"monitors\": {\"fluidised_time_s\": " << json_number(t_fluid >= 0 ? t_fluid : NAN)
      << ", \"outflow_median_second_half_l_s_10cm\": " << json_number(plateau) << ", \"gate_flux_median_second_half_l_s_10cm\": "
      << json_number(plateau_gate) << ", \"t_s\": [" << series(mon_t)
      << "], \"outflow_l_s_10cm\": [" << series(mon_q) << "], \"gate_flux_l_s_10cm\": [" << series(mon_gate)
      << "], \"gate_strain_rate_1_s\": [" << series(mon_sr)
      << "], \"moving_share\": [" << series(mon_moving) << "]";
    if (rotating) {
      // Once the material flows (after the first quarter of the samples that pass 90 % of the peak
      // angle): the mean and spread of the surface angle, and its mean over each quarter turn
      // (the box's 90 deg symmetry: a periodic response repeats every quarter turn).
      double peak_angle = 0;
      for (double a : mon_surface)
        if (!std::isnan(a)) peak_angle = std::max(peak_angle, a);
      double onset = NAN;
      for (std::size_t q = 0; q < mon_t.size(); ++q)
        if (!std::isnan(mon_surface[q]) && mon_surface[q] >= 0.9 * peak_angle) {
          onset = mon_t[q];
          break;
        }
      const double quarter = 0.25 * L.rotation_period_s();
      double sum_a = 0, sum_aa = 0, cnt = 0;
      std::vector<double> qsum(64, 0.0), qn(64, 0.0);
      for (std::size_t q = 0; q < mon_t.size(); ++q) {
        if (std::isnan(onset) || mon_t[q] < onset + 0.25 * quarter || std::isnan(mon_surface[q])) continue;
        sum_a += mon_surface[q], sum_aa += mon_surface[q] * mon_surface[q], cnt += 1;
        const auto k = std::min<std::size_t>(63, std::size_t(mon_t[q] / quarter));
        qsum[k] += mon_surface[q], qn[k] += 1;
      }
      const double mean = cnt > 0 ? sum_a / cnt : NAN;
      std::ostringstream qm;
      bool first = true;
      for (std::size_t k = 0; k < qsum.size(); ++k)
        if (qn[k] >= 0.5 * quarter / mon_every) {  // quarter turns sampled for at least half their length
          qm << (first ? "" : ", ") << json_number(qsum[k] / qn[k]);
          first = false;
        }
      j << ", \"surface_angle_onset_s\": " << json_number(onset) << ", \"surface_angle_mean_deg\": " << json_number(mean)
        << ", \"surface_angle_std_deg\": " << json_number(cnt > 1 ? std::sqrt(std::max(0.0, sum_aa / cnt - mean * mean)) : NAN)
        << ", \"surface_angle_quarter_turn_means_deg\": [" << qm.str() << "], \"surface_angle_deg\": [" << series(mon_surface) << "]";
    }
    if (end_wall) {
      // The shock's speed upstream: least-squares slope of its position over the samples that lie
      // between 0.1 m from the end wall and 80 % of the channel (clear of the corner and the inflow).
      double st = 0, sx = 0, stt = 0, stx = 0, n = 0, formed = NAN;
      const double len = L.x_max() - L.x_min();
      for (std::size_t q = 0; q < mon_t.size(); ++q) {
        const double xs = mon_shock[q];
        if (std::isnan(xs)) continue;
        if (std::isnan(formed)) formed = mon_t[q];
        const double d = L.x_max() - xs;
        if (d < 0.1 || d > 0.8 * len) continue;
        st += mon_t[q], sx += xs, stt += mon_t[q] * mon_t[q], stx += mon_t[q] * xs, n += 1;
      }
      const double speed = n >= 3 ? -(n * stx - st * sx) / (n * stt - st * st) : NAN;
      j << ", \"shock_formed_s\": " << json_number(formed) << ", \"shock_speed_upstream_m_s\": " << json_number(speed)
        << ", \"shock_samples_in_fit\": " << n << ", \"shock_x_m\": [" << series(mon_shock) << "]";
    }
    j << "},\n";
  }
  j << chute.str();
  j << "  \"timings_s\": {\"prepare\": " << json_number(sum.seconds_prepare) << ", \"run\": " << json_number(sum.seconds_run)
    << ", \"pressure\": " << json_number(pressure_s) << ", \"pressure_solve\": " << json_number(pressure_solve_s) << ", \"write\": " << json_number(sum.seconds_write) << ", \"microseconds_per_cell_step\": "
    << json_number(steps ? 1e6 * sum.seconds_run / steps / m.cells() : NAN) << ", \"microseconds_per_active_cell_step\": "
    << json_number(active_sum > 0 ? 1e6 * sum.seconds_run / active_sum : NAN) << "}\n}\n";
  if (!j) throw std::runtime_error("cannot write run.json");
  if (g.three_d) {
    figures::write_plan_figure(out_dir + "/comparison.png", plan);
    sum.files.push_back("comparison.png");
  } else {
    // comparison.png: the section with ours beside the scenario's reference values (lab.reference).
    figures::SectionFigure fig;
    fig.title = figure_title;
    fig.nx = g.nx, fig.ny = g.ny, fig.x0 = g.x0, fig.y0 = g.y0, fig.dx = dx, fig.dy = dy;
    fig.alpha.assign(std::size_t(g.nx) * g.ny, NAN);
    fig.ux.assign(fig.alpha.size(), 0.0);
    fig.uy.assign(fig.alpha.size(), 0.0);
    for (int jj = 0; jj < g.ny; ++jj)
      for (int i = 0; i < g.nx; ++i)
        if (const int c = g.id(i, jj, 0); c >= 0) {
          const std::size_t k = std::size_t(i) + std::size_t(g.nx) * std::size_t(jj);
          fig.alpha[k] = s.alpha()[std::size_t(c)];
          fig.ux[k] = s.velocity()[std::size_t(c)].x;
          fig.uy[k] = s.velocity()[std::size_t(c)].y;
        }
    double vmax = 0.01;
    for (int c = 0; c < m.cells(); ++c)
      if (s.alpha()[std::size_t(c)] > 0.5) vmax = std::max(vmax, vof::norm(s.velocity()[std::size_t(c)]));
    fig.vmax = vmax;
    if (!has_inflow) {  // the deposit figures of a collapse
      fig.front = front;
      fig.upper_angle = upper;
    }
    for (int i = imax; i < g.nx; ++i)
      if (h[std::size_t(i)] < 0.7 * hmax) {
        fig.anchor_x = g.x0 + (i + 0.5) * dx;
        break;
      }
    fig.height = hmax;
    fig.t = mon_t, fig.gate_flux = mon_gate, fig.outflow = mon_q, fig.moving = mon_moving;
    fig.fluidised = t_fluid >= 0 && !has_inflow ? t_fluid : NAN;
    if (end_wall)
      for (double x : mon_shock) fig.shock.push_back(L.x_max() - x);
    if (!gate_faces.empty()) {
      fig.gate_flux_early = median_between(mon_gate, 0.12, 0.30);
      fig.strain_early = median_between(mon_sr, 0.10, 0.20);
    }
    if (L.has_reference()) {
      const auto& ref = L.reference();
      fig.ref_source = ref.source();
      if (ref.has_front_x_min()) fig.ref_front_min = ref.front_x_min(), fig.ref_front_max = ref.front_x_max();
      if (ref.has_surface_angle_deg()) fig.ref_angle = ref.surface_angle_deg();
      if (ref.has_fluidised_time_s()) fig.ref_fluidised = ref.fluidised_time_s();
      if (ref.has_outflow_l_s()) fig.ref_outflow = ref.outflow_l_s();
      if (ref.has_gate_strain_rate_1_s()) fig.ref_strain = ref.gate_strain_rate_1_s();
    }
    figures::write_section_figure(out_dir + "/comparison.png", fig);
    sum.files.push_back("comparison.png");
  }
  return sum;
}

}  // namespace runout::jobs
