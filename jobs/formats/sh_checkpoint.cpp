#include "jobs/formats/sh_checkpoint.hpp"

#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <stdexcept>

#include "jobs/formats/h5_attr.hpp"
#include "jobs/scenario/scenario.hpp"
#include "jobs/formats/timeseries.hpp"

namespace runout::jobs {

namespace {

using h5::get_attr_string;
using h5::put_attr_string;

// The scalars, by position in the dataset "scalars" (their names are in its attribute "names").
constexpr const char* kScalarNames =
    "nx,ny,tile,t,steps,volume_initial,kinetic_energy_peak,cell_updates,active_fraction_sum,max_active_fraction,"
    "next_snapshot,last_snapshot,timeseries_frames,volume_secondary,secondary_areas,resistance_areas,erodible_cover,flux_gauges";
constexpr std::size_t kScalars = 18;

struct File {
  hid_t id = -1;
  ~File() {
    if (id >= 0) H5Fclose(id);
  }
};

// A dataset of `n` values of `file_type` from memory of `mem_type`; 2D (rows x cols) when rows > 0.
void put(hid_t f, const char* name, hid_t file_type, hid_t mem_type, const void* data, std::size_t n, hsize_t rows = 0) {
  const hsize_t dims[2] = {rows > 0 ? rows : hsize_t(n), rows > 0 ? hsize_t(n) / rows : 1};
  hid_t sp = H5Screate_simple(rows > 0 ? 2 : 1, dims, nullptr);
  hid_t ds = H5Dcreate2(f, name, file_type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t st = ds < 0 ? -1 : (n == 0 ? 0 : H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data));
  if (ds >= 0) H5Dclose(ds);
  H5Sclose(sp);
  if (st < 0) throw std::runtime_error(std::string("checkpoint: cannot write ") + name);
}

template <class T>
std::vector<T> get(hid_t f, const char* name, hid_t mem_type, std::size_t expect, const std::string& path) {
  if (H5Lexists(f, name, H5P_DEFAULT) <= 0) throw ScenarioError("checkpoint " + path + ": damaged (no dataset '" + name + "')");
  hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
  hid_t sp = H5Dget_space(ds);
  const hssize_t n = H5Sget_simple_extent_npoints(sp);
  H5Sclose(sp);
  if (n < 0 || std::size_t(n) != expect) {
    H5Dclose(ds);
    throw ScenarioError("checkpoint " + path + ": damaged ('" + name + "' holds " + std::to_string(n) + " values, not " +
                        std::to_string(expect) + ")");
  }
  std::vector<T> v(expect);
  const herr_t st = expect == 0 ? 0 : H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Dclose(ds);
  if (st < 0) throw ScenarioError("checkpoint " + path + ": cannot read '" + name + "'");
  return v;
}

}  // namespace

void write_sh_checkpoint(const std::string& path, const std::string& scenario_hash, int timeseries_frames,
                         const engine::Sh2dCheckpoint& s) {
  const std::string tmp = path + ".part";
  {
    std::lock_guard lk(hdf5_mutex());
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    File f;
    f.id = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (f.id < 0) throw std::runtime_error("cannot create the checkpoint " + tmp);
    try {
      put_attr_string(f.id, "format", kShCheckpointFormat);
      put_attr_string(f.id, "scenario_sha256", scenario_hash);
      const std::vector<double> sc = {double(s.nx), double(s.ny), double(s.tile), s.t, double(s.steps), s.volume_initial,
                                      s.kinetic_energy_peak, s.cell_updates, s.active_fraction_sum, s.max_active_fraction,
                                      s.next_snapshot, s.last_snapshot, double(timeseries_frames), s.volume_secondary,
                                      double(s.secondary_time.size()), s.detrained.empty() ? 0.0 : 1.0,
                                      s.cover.empty() ? 0.0 : 1.0, double(s.gauge_right.size())};
      put(f.id, "scalars", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, sc.data(), sc.size());
      hid_t ds = H5Dopen2(f.id, "scalars", H5P_DEFAULT);
      put_attr_string(ds, "names", kScalarNames);
      H5Dclose(ds);
      const hsize_t rows = hsize_t(s.ny);
      for (auto [name, v] : {std::pair<const char*, const std::vector<double>*>{"H", &s.H}, {"HU", &s.HU}, {"HV", &s.HV},
                             {"U", &s.U}, {"V", &s.V}, {"max_depth", &s.hazard.max_depth}, {"max_speed", &s.hazard.max_speed},
                             {"max_pressure", &s.hazard.max_pressure}, {"arrival_time", &s.hazard.arrival_time}})
        put(f.id, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, v->data(), v->size(), rows);
      for (auto [name, v] : {std::pair<const char*, const std::vector<double>*>{"tile_mass", &s.tile_mass}, {"tile_ke", &s.tile_ke},
                             {"tile_speed", &s.tile_speed}, {"tile_rate", &s.tile_rate}, {"tile_out", &s.tile_out},
                             {"tile_travel", &s.tile_travel}})
        put(f.id, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, v->data(), v->size());
      const std::vector<std::int64_t> limited(s.tile_limited.begin(), s.tile_limited.end());
      put(f.id, "tile_limited", H5T_STD_I64LE, H5T_NATIVE_INT64, limited.data(), limited.size());
      put(f.id, "tile_wet", H5T_STD_U8LE, H5T_NATIVE_UINT8, s.tile_wet.data(), s.tile_wet.size());
      put(f.id, "tile_active", H5T_STD_U8LE, H5T_NATIVE_UINT8, s.tile_active.data(), s.tile_active.size());
      put(f.id, "secondary_time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.secondary_time.data(), s.secondary_time.size());
      put(f.id, "gauge_right", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.gauge_right.data(), s.gauge_right.size());
      put(f.id, "gauge_left", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.gauge_left.data(), s.gauge_left.size());
      if (!s.detrained.empty()) {  // resistance areas: the depth detrained so far, per cell and per tile
        put(f.id, "detrained", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.detrained.data(), s.detrained.size(), rows);
        put(f.id, "tile_detrained", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.tile_detrained.data(), s.tile_detrained.size());
      }
      if (!s.cover.empty()) {  // an erodible cover: what is left of it per cell, and per tile the volume taken up
        put(f.id, "cover", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.cover.data(), s.cover.size(), rows);
        put(f.id, "tile_entrained", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, s.tile_entrained.data(), s.tile_entrained.size());
      }
    } catch (...) {
      H5Fclose(f.id);
      f.id = -1;
      std::filesystem::remove(tmp);
      throw;
    }
    const herr_t st = H5Fclose(f.id);
    f.id = -1;
    if (st < 0) throw std::runtime_error("cannot finish the checkpoint " + tmp);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("cannot move the checkpoint into place at " + path + ": " + ec.message());
}

ShCheckpoint read_sh_checkpoint(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw ScenarioError("checkpoint " + path + ": no such file");
  std::lock_guard lk(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (H5Fis_hdf5(path.c_str()) <= 0) throw ScenarioError("checkpoint " + path + ": not an HDF5 file");
  File f;
  f.id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f.id < 0) throw ScenarioError("checkpoint " + path + ": cannot open it");
  const std::string format = get_attr_string(f.id, "format");
  if (format.rfind("runout depth-averaged checkpoint ", 0) == 0 && format != kShCheckpointFormat)
    throw ScenarioError("checkpoint " + path + ": written by another build of runout (" + format + ", this build reads '" +
                        kShCheckpointFormat + "'); run the scenario again from the start");
  if (format != kShCheckpointFormat)
    throw ScenarioError("checkpoint " + path + ": not a checkpoint of a depth-averaged run" +
                        (format.empty() ? std::string() : " (it is a '" + format + "')"));
  ShCheckpoint cp;
  cp.scenario_hash = get_attr_string(f.id, "scenario_sha256");
  const auto sc = get<double>(f.id, "scalars", H5T_NATIVE_DOUBLE, kScalars, path);
  auto& s = cp.state;
  s.nx = int(sc[0]);
  s.ny = int(sc[1]);
  s.tile = int(sc[2]);
  s.t = sc[3];
  s.steps = long(sc[4]);
  s.volume_initial = sc[5];
  s.kinetic_energy_peak = sc[6];
  s.cell_updates = sc[7];
  s.active_fraction_sum = sc[8];
  s.max_active_fraction = sc[9];
  s.next_snapshot = sc[10];
  s.last_snapshot = sc[11];
  cp.timeseries_frames = int(sc[12]);
  s.volume_secondary = sc[13];
  if (!(sc[14] >= 0 && sc[14] < 1e6)) throw ScenarioError("checkpoint " + path + ": damaged (secondary release count)");
  if (!(s.nx > 0 && s.ny > 0 && s.tile > 0 && cp.timeseries_frames >= 0))
    throw ScenarioError("checkpoint " + path + ": damaged (grid or frame count)");
  const std::size_t n = std::size_t(s.nx) * std::size_t(s.ny);
  const std::size_t nt = std::size_t((s.nx + s.tile - 1) / s.tile) * std::size_t((s.ny + s.tile - 1) / s.tile);
  for (auto [name, v] : {std::pair<const char*, std::vector<double>*>{"H", &s.H}, {"HU", &s.HU}, {"HV", &s.HV}, {"U", &s.U},
                         {"V", &s.V}, {"max_depth", &s.hazard.max_depth}, {"max_speed", &s.hazard.max_speed},
                         {"max_pressure", &s.hazard.max_pressure}, {"arrival_time", &s.hazard.arrival_time}})
    *v = get<double>(f.id, name, H5T_NATIVE_DOUBLE, n, path);
  for (auto [name, v] : {std::pair<const char*, std::vector<double>*>{"tile_mass", &s.tile_mass}, {"tile_ke", &s.tile_ke},
                         {"tile_speed", &s.tile_speed}, {"tile_rate", &s.tile_rate}, {"tile_out", &s.tile_out},
                         {"tile_travel", &s.tile_travel}})
    *v = get<double>(f.id, name, H5T_NATIVE_DOUBLE, nt, path);
  const auto limited = get<std::int64_t>(f.id, "tile_limited", H5T_NATIVE_INT64, nt, path);
  s.tile_limited.assign(limited.begin(), limited.end());
  s.tile_wet = get<std::uint8_t>(f.id, "tile_wet", H5T_NATIVE_UINT8, nt, path);
  s.tile_active = get<std::uint8_t>(f.id, "tile_active", H5T_NATIVE_UINT8, nt, path);
  s.secondary_time = get<double>(f.id, "secondary_time", H5T_NATIVE_DOUBLE, std::size_t(sc[14]), path);
  if (!(sc[17] >= 0 && sc[17] < 1e6)) throw ScenarioError("checkpoint " + path + ": damaged (flux gauge count)");
  s.gauge_right = get<double>(f.id, "gauge_right", H5T_NATIVE_DOUBLE, std::size_t(sc[17]), path);
  s.gauge_left = get<double>(f.id, "gauge_left", H5T_NATIVE_DOUBLE, std::size_t(sc[17]), path);
  if (sc[15] != 0) {
    s.detrained = get<double>(f.id, "detrained", H5T_NATIVE_DOUBLE, n, path);
    s.tile_detrained = get<double>(f.id, "tile_detrained", H5T_NATIVE_DOUBLE, nt, path);
  }
  if (sc[16] != 0) {
    s.cover = get<double>(f.id, "cover", H5T_NATIVE_DOUBLE, n, path);
    s.tile_entrained = get<double>(f.id, "tile_entrained", H5T_NATIVE_DOUBLE, nt, path);
  }
  return cp;
}

}  // namespace runout::jobs
