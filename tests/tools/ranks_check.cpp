// ranks_check ONE MANY RANKS [FIGURE:RELTOL | RASTER.tif:ABSTOL | RASTER.tif:P%]...: a run split over MPI ranks
// (results in MANY) against the same run on one process (ONE). Reads both run.json as
// runout.v1.RunRecord; MANY's record must say it ran on RANKS ranks and ONE's on one. Each figure
// (jobs::figure_by_name) must agree within its relative tolerance; each raster must have the same
// cells with data and agree within its absolute tolerance on them (P%: P percent of the largest
// value ONE's raster holds). Prints a line per check; exits 1
// when one fails, 2 on a bad command line. The mpi tests (tests/mpi/run_on_ranks.sh) use it.
#include <gdal_priv.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "jobs/formats/run_record.hpp"

namespace {

struct Raster {
  std::vector<double> v;
  std::vector<char> ok;
};

Raster read_raster(const std::string& path) {
  Raster r;
  GDALDataset* ds = static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly));
  if (!ds) throw std::runtime_error("cannot open " + path);
  GDALRasterBand* b = ds->GetRasterBand(1);
  const int w = ds->GetRasterXSize(), h = ds->GetRasterYSize();
  int has = 0;
  const double nodata = b->GetNoDataValue(&has);
  r.v.resize(std::size_t(w) * h);
  if (b->RasterIO(GF_Read, 0, 0, w, h, r.v.data(), w, h, GDT_Float64, 0, 0) != CE_None) throw std::runtime_error("cannot read " + path);
  r.ok.resize(r.v.size());
  for (std::size_t k = 0; k < r.v.size(); ++k) r.ok[k] = std::isfinite(r.v[k]) && !(has && r.v[k] == nodata);
  GDALClose(ds);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: ranks_check ONE MANY RANKS [FIGURE:RELTOL | RASTER.tif:ABSTOL | RASTER.tif:P%%]...\n");
    return 2;
  }
  GDALAllRegister();
  const std::string one = argv[1], many = argv[2];
  const int ranks = std::atoi(argv[3]);
  int failed = 0;
  try {
    const auto a = runout::jobs::read_run_record(one + "/run.json"), b = runout::jobs::read_run_record(many + "/run.json");
    const auto& d = b.execution().distribution();
    std::printf("ranks %d (one process: %d); %lld cells, %lld faces cut, imbalance %.3f, ghosts %.1f %%, %.1f exchanges and %.0f bytes per step\n",
                d.ranks(), a.execution().distribution().ranks(), (long long)d.cells(), (long long)d.cut_faces(), d.imbalance(),
                100 * d.ghost_share(), d.exchanges_per_step(), d.halo_bytes_per_step());
    if (d.ranks() != ranks || a.execution().has_distribution()) {
      std::printf("FAIL: the records do not say %d ranks and one process\n", ranks);
      ++failed;
    }
    for (int k = 4; k < argc; ++k) {
      const std::string arg = argv[k];
      const auto colon = arg.rfind(':');
      if (colon == std::string::npos) {
        std::fprintf(stderr, "ranks_check: '%s' has no tolerance\n", arg.c_str());
        return 2;
      }
      const std::string name = arg.substr(0, colon), limit = arg.substr(colon + 1);
      double tol = std::atof(limit.c_str());
      if (name.size() > 4 && name.substr(name.size() - 4) == ".tif") {
        const auto x = read_raster(one + "/" + name), y = read_raster(many + "/" + name);
        double worst = 0, top = 0;
        long long only = 0;
        for (std::size_t q = 0; q < x.v.size() && q < y.v.size(); ++q) {
          if (x.ok[q] != y.ok[q]) ++only;
          else if (x.ok[q]) worst = std::max(worst, std::abs(x.v[q] - y.v[q]));
          if (x.ok[q]) top = std::max(top, std::abs(x.v[q]));
        }
        if (!limit.empty() && limit.back() == '%') tol *= top / 100;  // "2%": of the one process's largest value
        const bool ok = x.v.size() == y.v.size() && only == 0 && worst <= tol;
        std::printf("%s %s: largest difference %.3g (limit %.3g), cells with data in one only %lld\n", ok ? "ok  " : "FAIL", name.c_str(), worst, tol,
                    only);
        failed += ok ? 0 : 1;
      } else {
        const double x = runout::jobs::figure_by_name(a, name), y = runout::jobs::figure_by_name(b, name);
        const double rel = std::abs(x - y) / std::max(std::abs(x), 1e-300);
        const bool ok = std::isfinite(x) && std::isfinite(y) && (x == y || rel <= tol);
        std::printf("%s %s: %.10g vs %.10g (relative %.2e, limit %.2e)\n", ok ? "ok  " : "FAIL", name.c_str(), x, y, rel, tol);
        failed += ok ? 0 : 1;
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ranks_check: %s\n", e.what());
    return 1;
  }
  return failed == 0 ? 0 : 1;
}
