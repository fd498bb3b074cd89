#include "jobs/formats/checkpoint.hpp"

#include <hdf5.h>

#include <filesystem>
#include <mutex>

#include "jobs/formats/h5_attr.hpp"
#include "jobs/scenario/scenario.hpp"
#include "jobs/formats/timeseries.hpp"

namespace runout::jobs {

namespace {

using h5::get_attr_string;
using h5::put_attr_string;

// 3: with the pressure solver's cross-step state (the operators its preconditioner was built from),
// without which a continued run is not the uninterrupted run bit for bit.
constexpr const char* kFormat = "runout VOF checkpoint 3";

void put_doubles(hid_t g, const char* name, const std::vector<double>& v, hsize_t cols = 1) {
  const hsize_t dims[2] = {hsize_t(v.size()) / cols, cols};
  hid_t sp = H5Screate_simple(cols > 1 ? 2 : 1, dims, nullptr);
  hid_t ds = H5Dcreate2(g, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const herr_t st = H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Dclose(ds);
  H5Sclose(sp);
  if (st < 0) throw std::runtime_error(std::string("checkpoint: cannot write ") + name);
}

template <class T>
std::vector<T> get(hid_t g, const char* name, hid_t mem_type, const std::string& path) {
  if (H5Lexists(g, name, H5P_DEFAULT) <= 0) throw ScenarioError("checkpoint " + path + ": no dataset '" + name + "'");
  hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
  hid_t sp = H5Dget_space(ds);
  const hssize_t n = H5Sget_simple_extent_npoints(sp);
  std::vector<T> v(static_cast<std::size_t>(std::max<hssize_t>(n, 0)));
  const herr_t st = v.empty() ? 0 : H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(sp);
  H5Dclose(ds);
  if (st < 0) throw ScenarioError("checkpoint " + path + ": cannot read '" + name + "'");
  return v;
}

}  // namespace

void write_checkpoint(const std::string& path, const VofCheckpoint& cp) {
  const std::string tmp = path + ".part";
  {
    std::lock_guard lk(hdf5_mutex());
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    hid_t f = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (f < 0) throw std::runtime_error("cannot create the checkpoint " + tmp);
    try {
      put_attr_string(f, "format", kFormat);
      put_attr_string(f, "scenario_sha256", cp.scenario_hash);
      const auto& s = cp.state;
      std::vector<double> scalars = {s.t, s.dt, double(cp.steps)};
      put_doubles(f, "time_dt_steps", scalars);
      std::vector<double> fig;
      std::string names;
      for (const auto& [k, v] : cp.figures) {
        fig.push_back(v);
        names += (names.empty() ? "" : ",") + k;
      }
      put_attr_string(f, "figure_names", names);
      put_doubles(f, "figures", fig);
      for (auto [name, v] : {std::pair<const char*, const std::vector<double>*>{"alpha", &s.alpha}, {"p_rgh", &s.p_rgh}, {"p", &s.p},
                             {"nu1", &s.nu1}, {"mu", &s.mu}, {"phi", &s.phi}})
        put_doubles(f, name, *v);
      std::vector<double> U;
      U.reserve(s.U.size() * 3);
      for (const auto& u : s.U) U.insert(U.end(), {u.x, u.y, u.z});
      put_doubles(f, "U", U, 3);
      std::vector<double> act(s.active_cells.begin(), s.active_cells.end());
      put_doubles(f, "active_cells", act);
      // The pressure solver's state (integers as doubles: exact far beyond any mesh's size).
      put_doubles(f, "pressure_pc_counters", {double(s.steps_since_pc), double(s.pc_builds)});
      put_doubles(f, "pressure_pc_rows", std::vector<double>(s.pc_rows.begin(), s.pc_rows.end()));
      put_doubles(f, "pressure_pc_cols", std::vector<double>(s.pc_cols.begin(), s.pc_cols.end()));
      put_doubles(f, "pressure_pc_first_values", s.pc_first_values);
      put_doubles(f, "pressure_pc_values", s.pc_values);
      hid_t g = H5Gcreate2(f, "series", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      if (g < 0) throw std::runtime_error("checkpoint: cannot write the series");
      try {
        for (const auto& [k, v] : cp.series) put_doubles(g, k.c_str(), v);
      } catch (...) {
        H5Gclose(g);
        throw;
      }
      H5Gclose(g);
    } catch (...) {
      H5Fclose(f);
      std::filesystem::remove(tmp);
      throw;
    }
    if (H5Fclose(f) < 0) throw std::runtime_error("cannot finish the checkpoint " + tmp);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("cannot move the checkpoint into place at " + path + ": " + ec.message());
}

VofCheckpoint read_checkpoint(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw ScenarioError("checkpoint " + path + ": no such file");
  std::lock_guard lk(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (H5Fis_hdf5(path.c_str()) <= 0) throw ScenarioError("checkpoint " + path + ": not an HDF5 file");
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw ScenarioError("checkpoint " + path + ": cannot open it");
  VofCheckpoint cp;
  try {
    const std::string format = get_attr_string(f, "format");
    if (format.rfind("runout VOF checkpoint ", 0) == 0 && format != kFormat)
      throw ScenarioError("checkpoint " + path + ": written by another build of runout (" + format + ", this build reads '" + kFormat +
                          "'); run the scenario again from the start");
    if (format != kFormat) throw ScenarioError("checkpoint " + path + ": not a runout VOF checkpoint");
    cp.scenario_hash = get_attr_string(f, "scenario_sha256");
    const auto sc = get<double>(f, "time_dt_steps", H5T_NATIVE_DOUBLE, path);
    if (sc.size() != 3) throw ScenarioError("checkpoint " + path + ": damaged (time_dt_steps)");
    auto& s = cp.state;
    s.t = sc[0];
    s.dt = sc[1];
    cp.steps = long(sc[2]);
    const auto fig = get<double>(f, "figures", H5T_NATIVE_DOUBLE, path);
    const std::string names = get_attr_string(f, "figure_names");
    std::size_t k = 0, pos = 0;
    while (!names.empty() && pos <= names.size() && k < fig.size()) {
      const auto e = names.find(',', pos);
      cp.figures[names.substr(pos, e == std::string::npos ? std::string::npos : e - pos)] = fig[k++];
      if (e == std::string::npos) break;
      pos = e + 1;
    }
    s.alpha = get<double>(f, "alpha", H5T_NATIVE_DOUBLE, path);
    s.p_rgh = get<double>(f, "p_rgh", H5T_NATIVE_DOUBLE, path);
    s.p = get<double>(f, "p", H5T_NATIVE_DOUBLE, path);
    s.nu1 = get<double>(f, "nu1", H5T_NATIVE_DOUBLE, path);
    s.mu = get<double>(f, "mu", H5T_NATIVE_DOUBLE, path);
    s.phi = get<double>(f, "phi", H5T_NATIVE_DOUBLE, path);
    const auto U = get<double>(f, "U", H5T_NATIVE_DOUBLE, path);
    if (U.size() % 3) throw ScenarioError("checkpoint " + path + ": damaged (U)");
    for (std::size_t i = 0; i + 2 < U.size(); i += 3) s.U.push_back({U[i], U[i + 1], U[i + 2]});
    for (double a : get<double>(f, "active_cells", H5T_NATIVE_DOUBLE, path)) s.active_cells.push_back(int(a));
    const auto pcc = get<double>(f, "pressure_pc_counters", H5T_NATIVE_DOUBLE, path);
    if (pcc.size() != 2) throw ScenarioError("checkpoint " + path + ": damaged (pressure_pc_counters)");
    s.steps_since_pc = int(pcc[0]);
    s.pc_builds = int(pcc[1]);
    for (double v : get<double>(f, "pressure_pc_rows", H5T_NATIVE_DOUBLE, path)) s.pc_rows.push_back(int(v));
    for (double v : get<double>(f, "pressure_pc_cols", H5T_NATIVE_DOUBLE, path)) s.pc_cols.push_back(int(v));
    s.pc_first_values = get<double>(f, "pressure_pc_first_values", H5T_NATIVE_DOUBLE, path);
    s.pc_values = get<double>(f, "pressure_pc_values", H5T_NATIVE_DOUBLE, path);
    if (H5Lexists(f, "series", H5P_DEFAULT) <= 0) throw ScenarioError("checkpoint " + path + ": damaged (no series)");
    hid_t g = H5Gopen2(f, "series", H5P_DEFAULT);
    H5G_info_t info;
    if (g < 0 || H5Gget_info(g, &info) < 0) {
      if (g >= 0) H5Gclose(g);
      throw ScenarioError("checkpoint " + path + ": damaged (series)");
    }
    try {
      for (hsize_t q = 0; q < info.nlinks; ++q) {
        char name[256];
        if (H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, q, name, sizeof name, H5P_DEFAULT) < 0)
          throw ScenarioError("checkpoint " + path + ": damaged (series)");
        cp.series[name] = get<double>(g, name, H5T_NATIVE_DOUBLE, path);
      }
    } catch (...) {
      H5Gclose(g);
      throw;
    }
    H5Gclose(g);
  } catch (...) {
    H5Fclose(f);
    throw;
  }
  H5Fclose(f);
  return cp;
}

}  // namespace runout::jobs
