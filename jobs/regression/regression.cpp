#include "jobs/regression/regression.hpp"

#include "jobs/figures/hazard_map.hpp"
#include "jobs/figures/pen.hpp"

#include <gdal_priv.h>
#include <google/protobuf/util/json_util.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "jobs/system/store.hpp"
#include "jobs/formats/run_record.hpp"
#include "runout/v1/regression.pb.h"


namespace fs = std::filesystem;

namespace runout::jobs {

namespace {

constexpr double kFarmLon = 9.8539, kFarmLat = 46.8367;  // validation.md C1

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw std::runtime_error("cannot read '" + p.string() + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A figure or tolerance the reference must hold: `what` names it in the error.
double required(bool has, double v, const std::string& what) {
  if (!has) throw std::runtime_error("reference: no '" + what + "'");
  return v;
}

struct Raster {
  int nx = 0, ny = 0;
  double gt[6] = {0, 1, 0, 0, 0, -1};
  std::string wkt;
  std::vector<float> v;
  float nodata = -9999.0f;
};

Raster read_raster(const std::string& path) {
  GDALAllRegister();
  GDALDatasetUniquePtr d(GDALDataset::Open(path.c_str(), GDAL_OF_RASTER));
  if (!d) throw std::runtime_error("cannot read raster '" + path + "'");
  Raster r;
  r.nx = d->GetRasterXSize();
  r.ny = d->GetRasterYSize();
  d->GetGeoTransform(r.gt);
  if (const auto* s = d->GetSpatialRef()) {
    char* w = nullptr;
    s->exportToWkt(&w);
    r.wkt = w ? w : "";
    CPLFree(w);
  }
  int has = 0;
  const double nd = d->GetRasterBand(1)->GetNoDataValue(&has);
  if (has) r.nodata = float(nd);
  r.v.resize(std::size_t(r.nx) * r.ny);
  if (d->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, r.nx, r.ny, r.v.data(), r.nx, r.ny, GDT_Float32, 0, 0) != CE_None)
    throw std::runtime_error("reading raster '" + path + "' failed");
  return r;
}

std::string fmt(double v, int prec = 6) {
  std::ostringstream o;
  o.precision(prec);
  o << v;
  return o.str();
}

}  // namespace

RegressionFigures measure_run(const std::string& results_dir, bool farmhouse_optional) {
  const std::string path = (fs::path(results_dir) / "run.json").string();
  const auto rec = read_run_record(path);
  if (!rec.has_results() || !rec.results().has_runout_from_release_centroid_m() || !rec.solver().has_max_speed_m_s() || !rec.has_mass_balance())
    throw std::runtime_error("run record " + path + " is not a finished hazard run's (no results, solver or mass balance)");
  RegressionFigures f;
  f.runout_m = rec.results().runout_from_release_centroid_m();
  f.affected_area_m2 = rec.results().affected_area_m2();
  f.max_depth_m = rec.results().max_depth_m();
  f.max_speed_m_s = rec.solver().max_speed_m_s();
  f.volume_error = rec.mass_balance().relative_error();
  if (rec.results().path().has_runout_s_m()) {
    f.path_runout_m = rec.results().path().runout_s_m();
    f.path_alpha_deg = rec.results().path().alpha_deg();
    f.path_criterion = rec.results().path().criterion() + ", " + rec.results().path().source();
  }
  const Raster r = read_raster((fs::path(results_dir) / "max_depth.tif").string());
  OGRSpatialReference ll, grid;
  ll.importFromEPSG(4326);
  ll.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  if (grid.importFromWkt(r.wkt.c_str()) != OGRERR_NONE || grid.IsLocal())
    throw std::runtime_error("max_depth.tif has no geographic CRS: the farmhouse cannot be placed");
  grid.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&ll, &grid));
  double x = kFarmLon, y = kFarmLat;
  if (!ct || !ct->Transform(1, &x, &y)) throw std::runtime_error("cannot place the farmhouse in the run's CRS");
  const int i = int(std::floor((x - r.gt[0]) / r.gt[1])), j = int(std::floor((y - r.gt[3]) / r.gt[5]));
  if (i < 0 || j < 0 || i >= r.nx || j >= r.ny) {
    if (!farmhouse_optional) throw std::runtime_error("the farmhouse lies outside the run's grid");
    f.farmhouse_depth_m = f.farmhouse_distance_m = std::numeric_limits<double>::quiet_NaN();
    return f;
  }
  const float here = r.v[std::size_t(j) * r.nx + i];
  f.farmhouse_depth_m = here == r.nodata ? 0.0 : double(here);
  double best = std::numeric_limits<double>::infinity();
  for (int q = 0; q < r.ny; ++q)
    for (int p = 0; p < r.nx; ++p) {
      const float v = r.v[std::size_t(q) * r.nx + p];
      if (v == r.nodata || v < 0.1f) continue;
      if (p == i && q == j) best = 0;
      const double cx = r.gt[0] + (p + 0.5) * r.gt[1], cy = r.gt[3] + (q + 0.5) * r.gt[5];
      best = std::min(best, std::hypot(cx - x, cy - y));
    }
  f.farmhouse_distance_m = std::isfinite(best) ? best : 1e9;
  return f;
}

RegressionReference read_reference(const std::string& reference_dir) {
  const fs::path p = fs::path(reference_dir) / "reference.json";
  if (!fs::exists(p))
    throw std::runtime_error("no reference in '" + reference_dir + "' (accept a run first: runout regress --accept --reason TEXT)");
  v1::RegressionReference m;
  const auto st = google::protobuf::util::JsonStringToMessage(slurp(p), &m);
  if (!st.ok()) throw std::runtime_error("'" + p.string() + "': " + std::string(st.message()));
  const auto& f = m.figures();
  const auto& t = m.tolerances();
  RegressionReference r;
  r.figures.runout_m = required(f.has_runout_m(), f.runout_m(), "figures.runout_m");
  r.figures.affected_area_m2 = required(f.has_affected_area_m2(), f.affected_area_m2(), "figures.affected_area_m2");
  r.figures.max_depth_m = required(f.has_max_depth_m(), f.max_depth_m(), "figures.max_depth_m");
  r.figures.max_speed_m_s = required(f.has_max_speed_m_s(), f.max_speed_m_s(), "figures.max_speed_m_s");
  r.figures.volume_error = required(f.has_volume_error(), f.volume_error(), "figures.volume_error");
  r.figures.farmhouse_depth_m = required(f.has_farmhouse_depth_m(), f.farmhouse_depth_m(), "figures.farmhouse_depth_m");
  r.figures.farmhouse_distance_m = required(f.has_farmhouse_distance_m(), f.farmhouse_distance_m(), "figures.farmhouse_distance_m");
  r.tolerances.runout_rel = required(t.has_runout_rel(), t.runout_rel(), "tolerances.runout_rel");
  r.tolerances.area_rel = required(t.has_area_rel(), t.area_rel(), "tolerances.area_rel");
  r.tolerances.max_depth_rel = required(t.has_max_depth_rel(), t.max_depth_rel(), "tolerances.max_depth_rel");
  r.tolerances.max_speed_rel = required(t.has_max_speed_rel(), t.max_speed_rel(), "tolerances.max_speed_rel");
  r.tolerances.volume_error_abs = required(t.has_volume_error_abs(), t.volume_error_abs(), "tolerances.volume_error_abs");
  r.tolerances.farmhouse_distance_abs = required(t.has_farmhouse_distance_abs(), t.farmhouse_distance_abs(), "tolerances.farmhouse_distance_abs");
  r.tolerances.depth_map_abs = required(t.has_depth_map_abs(), t.depth_map_abs(), "tolerances.depth_map_abs");
  r.accepted_utc = m.accepted_utc();
  r.reason = m.reason();
  r.software_version = m.software_version();
  r.scenario_hash = m.scenario_hash();
  return r;
}

namespace {

// diff.tif: the run minus the reference maximum depth, -9999 where either has no data.
void write_diff_tif(const Raster& a, std::vector<float>& d, const std::string& out_dir) {
  GDALAllRegister();
  auto* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
  const char* opts[] = {"COMPRESS=DEFLATE", nullptr};
  GDALDatasetUniquePtr tif(gtiff->Create((fs::path(out_dir) / "diff.tif").c_str(), a.nx, a.ny, 1, GDT_Float32,
                                         const_cast<char**>(opts)));
  if (!tif) throw std::runtime_error("cannot write diff.tif");
  tif->SetGeoTransform(const_cast<double*>(a.gt));
  tif->SetProjection(a.wkt.c_str());
  tif->GetRasterBand(1)->SetNoDataValue(-9999);
  tif->GetRasterBand(1)->SetDescription("run minus reference maximum depth [m]");
  if (tif->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, a.nx, a.ny, d.data(), a.nx, a.ny, GDT_Float32, 0, 0) != CE_None)
    throw std::runtime_error("writing diff.tif failed");
}

void write_diff_png(const Raster& a, const Raster& b, const std::vector<float>& d, double scale, const std::string& out_dir) {
  // diff.png, drawn by the map room: the difference in five classes of the scale (full colour at
  // max(0.1 m, the largest difference)), red where the run is deeper, blue where shallower; the
  // reference's outline (max depth > 0.1 m). No DEM comes with the rasters: a plain background.
  terrain::Grid g;
  g.nx = a.nx;
  g.ny = a.ny;
  g.dx = a.gt[1];
  g.x_min = a.gt[0];
  g.y_min = a.gt[3] + a.ny * a.gt[5];
  g.crs_wkt = a.wkt;
  OGRSpatialReference srs;
  srs.importFromWkt(a.wkt.c_str());
  g.crs_name = srs.GetAuthorityCode(nullptr) ? std::string("EPSG:") + srs.GetAuthorityCode(nullptr) : std::string(srs.GetName() ? srs.GetName() : "");
  g.z.assign(g.cells(), 0.0);
  g.outside.assign(g.cells(), 0);
  figures::HazardMap m;
  m.title = "In den Arelen regression: maximum depth, this run minus the reference";
  const std::string u = " m";
  auto n = [](double v) { return figures::label_number(std::round(v * 1000) / 1000); };
  m.palette = {"difference of the maximum depth", "m",
               {{-1e300, {{33, 102, 172}}, "< " + n(-scale / 2) + u},
                {-scale / 2, {{146, 197, 222}}, n(-scale / 2) + " – " + n(-scale / 10) + u},
                {-scale / 10, {{247, 247, 247}}, "within ±" + n(scale / 10) + u},
                {scale / 10, {{244, 165, 130}}, n(scale / 10) + " – " + n(scale / 2) + u},
                {scale / 2, {{178, 24, 43}}, "≥ " + n(scale / 2) + u}}};
  m.values.assign(g.cells(), NAN);
  m.max_depth.assign(g.cells(), 0.0);
  for (int r = 0; r < a.ny; ++r)
    for (int i = 0; i < a.nx; ++i) {
      const std::size_t src = std::size_t(r) * a.nx + i, k = std::size_t(a.ny - 1 - r) * a.nx + i;  // rows north first -> south first
      if (d[src] == -9999.0f) g.outside[k] = 1;
      else m.values[k] = d[src];
      m.max_depth[k] = b.v[src] == b.nodata ? 0.0 : b.v[src];
    }
  m.parameters = {"the outline is the reference's", "full colour at " + n(scale) + " m (0.1 m or the largest difference)"};
  figures::draw_hazard_map((fs::path(out_dir) / "diff.png").string(), "", g, m);
}

}  // namespace

RegressionOutcome compare_run(const RegressionFigures& run, const RegressionReference& ref, const std::string& run_max_depth,
                              const std::string& reference_dir, const std::string& out_dir) {
  RegressionOutcome o;
  const auto& rf = ref.figures;
  const auto& t = ref.tolerances;
  auto rel = [&](const char* name, const char* unit, double r, double v, double tol) {
    RegressionRow row{name, unit, r, v, v - r, tol, true};
    row.ok = std::abs(v - r) <= tol * std::abs(r);
    o.rows.push_back(row);
  };
  rel("runout from the release centroid", "m", rf.runout_m, run.runout_m, t.runout_rel);
  rel("affected area (max depth > 0.1 m)", "m2", rf.affected_area_m2, run.affected_area_m2, t.area_rel);
  rel("maximum depth", "m", rf.max_depth_m, run.max_depth_m, t.max_depth_rel);
  rel("maximum speed", "m/s", rf.max_speed_m_s, run.max_speed_m_s, t.max_speed_rel);
  if (std::isfinite(run.path_runout_m))
    o.path_note = "Runout along the path: " + fmt(run.path_runout_m) + " m (" + run.path_criterion + "), runout angle alpha " +
                  fmt(run.path_alpha_deg, 3) + " deg; reported, not compared.";
  o.rows.push_back({"relative volume error", "", rf.volume_error, run.volume_error, run.volume_error - rf.volume_error,
                    t.volume_error_abs, std::abs(run.volume_error) <= t.volume_error_abs});
  o.rows.push_back({"farmhouse: distance to the flow (0: reached)", "m", rf.farmhouse_distance_m, run.farmhouse_distance_m,
                    run.farmhouse_distance_m - rf.farmhouse_distance_m, t.farmhouse_distance_abs,
                    run.farmhouse_distance_m <= rf.farmhouse_distance_m + t.farmhouse_distance_abs});
  o.rows.push_back({"farmhouse: maximum depth", "m", rf.farmhouse_depth_m, run.farmhouse_depth_m,
                    run.farmhouse_depth_m - rf.farmhouse_depth_m, 0, true});  // reported, not checked

  // The depth maps, cell by cell.
  const Raster a = read_raster(run_max_depth);
  const Raster b = read_raster((fs::path(reference_dir) / "max_depth.tif").string());
  bool same_grid = a.nx == b.nx && a.ny == b.ny;
  for (int k = 0; k < 6 && same_grid; ++k) same_grid = std::abs(a.gt[k] - b.gt[k]) <= 1e-6 * std::max(1.0, std::abs(b.gt[k]));
  RegressionRow map{"max-depth map: largest abs(run - reference)", "m", 0, 0, 0, t.depth_map_abs, true};
  if (!same_grid) {
    map.ok = false;
    o.note = "the run's grid differs from the reference's (" + std::to_string(a.nx) + " x " + std::to_string(a.ny) + " vs " +
             std::to_string(b.nx) + " x " + std::to_string(b.ny) + "): no difference map";
  } else {
    std::vector<float> d(a.v.size(), -9999.0f);
    double worst = 0;
    for (std::size_t k = 0; k < d.size(); ++k) {
      const bool na = a.v[k] == a.nodata, nb = b.v[k] == b.nodata;
      if (na || nb) continue;
      d[k] = a.v[k] - b.v[k];
      if (a.v[k] > 0.1f || b.v[k] > 0.1f) worst = std::max(worst, double(std::abs(d[k])));
    }
    map.value = worst;
    map.difference = worst;
    map.ok = worst <= t.depth_map_abs;
    write_diff_tif(a, d, out_dir);
    const double scale = std::max(0.1, worst);
    write_diff_png(a, b, d, scale, out_dir);
    o.note = "diff.png: red where this run is deeper, blue where shallower, full colour at " + fmt(scale, 3) +
             " m; black: the reference outline (0.1 m)";
  }
  o.rows.push_back(map);
  for (const auto& r : o.rows) o.ok &= r.ok;
  return o;
}

void write_report(const std::string& out_dir, const RegressionOutcome& o, const RegressionReference& ref,
                  const std::string& job_id, const std::string& scenario_hash, double wall_s) {
  std::ofstream r(fs::path(out_dir) / "report.md");
  r << "# In den Arelen regression: " << (o.ok ? "PASS" : "REGRESSION") << "\n\n";
  r << "Run " << utc_now() << ", job " << job_id << ", scenario " << scenario_hash.substr(0, 16) << ", " << fmt(wall_s, 3)
    << " s from submission to results.\n";
  r << "Reference accepted " << ref.accepted_utc << " (runout " << ref.software_version << "): " << ref.reason << "\n";
  if (!ref.scenario_hash.empty() && ref.scenario_hash != scenario_hash)
    r << "\nThe scenario or its inputs changed since the reference (hash " << ref.scenario_hash.substr(0, 16) << ").\n";
  r << "\n| figure | reference | this run | difference | tolerance | |\n|---|---:|---:|---:|---:|---|\n";
  for (const auto& row : o.rows) {
    std::string tol = row.tolerance == 0 ? "reported" : fmt(row.tolerance, 3);
    if (row.name.rfind("runout", 0) == 0 || row.name.rfind("affected", 0) == 0 || row.name.rfind("maximum", 0) == 0)
      tol = fmt(100 * row.tolerance, 3) + " %";
    r << "| " << row.name << (row.unit.empty() ? "" : " [" + row.unit + "]") << " | " << fmt(row.reference) << " | "
      << fmt(row.value) << " | " << fmt(row.difference, 4) << " | " << tol << " | " << (row.ok ? "ok" : "**FAIL**") << " |\n";
  }
  if (!o.path_note.empty()) r << "\n" << o.path_note << "\n";
  if (!o.note.empty()) r << "\n" << o.note << "\n";
  r << "\n## Map of this run\n\n![map](map.png)\n";
  if (fs::exists(fs::path(out_dir) / "diff.png")) r << "\n## Difference of the maximum depth (run - reference)\n\n![difference](diff.png)\n";
  if (!r) throw std::runtime_error("cannot write report.md");
}

void accept_reference(const std::string& reference_dir, const RegressionFigures& f, const std::string& run_max_depth,
                      const std::string& reason, const std::string& scenario_hash, const std::string& version) {
  RegressionTolerances t;
  try {
    t = read_reference(reference_dir).tolerances;  // kept from the previous reference
  } catch (const std::exception&) {
  }
  fs::create_directories(reference_dir);
  const std::string now = utc_now();
  v1::RegressionReference m;
  m.set_accepted_utc(now);
  m.set_reason(reason);
  m.set_software_version(version);
  m.set_scenario_hash(scenario_hash);
  auto* fig = m.mutable_figures();
  fig->set_runout_m(f.runout_m);
  fig->set_affected_area_m2(f.affected_area_m2);
  fig->set_max_depth_m(f.max_depth_m);
  fig->set_max_speed_m_s(f.max_speed_m_s);
  fig->set_volume_error(f.volume_error);
  fig->set_farmhouse_depth_m(f.farmhouse_depth_m);
  fig->set_farmhouse_distance_m(f.farmhouse_distance_m);
  auto* tol = m.mutable_tolerances();
  tol->set_runout_rel(t.runout_rel);
  tol->set_area_rel(t.area_rel);
  tol->set_max_depth_rel(t.max_depth_rel);
  tol->set_max_speed_rel(t.max_speed_rel);
  tol->set_volume_error_abs(t.volume_error_abs);
  tol->set_farmhouse_distance_abs(t.farmhouse_distance_abs);
  tol->set_depth_map_abs(t.depth_map_abs);
  std::string json;
  google::protobuf::util::JsonPrintOptions o;
  o.preserve_proto_field_names = true;
  o.add_whitespace = true;
  if (!google::protobuf::util::MessageToJsonString(m, &json, o).ok()) throw std::runtime_error("cannot write the reference as JSON");
  std::ofstream j(fs::path(reference_dir) / "reference.json");
  j << json;
  if (!j) throw std::runtime_error("cannot write the reference");
  fs::copy_file(run_max_depth, fs::path(reference_dir) / "max_depth.tif", fs::copy_options::overwrite_existing);
  std::ofstream h(fs::path(reference_dir) / "HISTORY.md", std::ios::app);
  h << "- " << now << " (runout " << version << "): " << reason << ". Runout " << fmt(f.runout_m, 5) << " m, area "
    << fmt(f.affected_area_m2, 6) << " m2, max depth " << fmt(f.max_depth_m, 4) << " m, max speed " << fmt(f.max_speed_m_s, 4)
    << " m/s, farmhouse " << (f.farmhouse_distance_m == 0 ? "reached" : "missed by " + fmt(f.farmhouse_distance_m, 4) + " m")
    << ".\n";
}

}  // namespace runout::jobs
