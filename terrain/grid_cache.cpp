// The terrain cache: a prepared grid (the DEM warped, resampled and clipped) saved so that runs on
// the same DEM, area and grid (an ensemble's members) read it instead of preparing it again.
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "terrain/terrain.hpp"

namespace runout::terrain {

namespace {

constexpr char kMagic[] = "runout terrain cache 1\n";

template <class T>
void put(std::ostream& o, const T& v) {
  o.write(reinterpret_cast<const char*>(&v), sizeof v);
}
void put_text(std::ostream& o, const std::string& s) {
  put(o, std::uint64_t(s.size()));
  o.write(s.data(), std::streamsize(s.size()));
}
template <class T>
bool get(std::istream& i, T& v) {
  return bool(i.read(reinterpret_cast<char*>(&v), sizeof v));
}
bool get_text(std::istream& i, std::string& s) {
  std::uint64_t n = 0;
  if (!get(i, n) || n > (1u << 24)) return false;
  s.resize(n);
  return bool(i.read(s.data(), std::streamsize(n)));
}

}  // namespace

void save_grid(const std::string& path, const Grid& g, const DemReport& r) {
  const std::string tmp = path + ".tmp-" + std::to_string(getpid());
  {
    std::ofstream o(tmp, std::ios::binary | std::ios::trunc);
    o.write(kMagic, sizeof kMagic - 1);
    put(o, g.nx);
    put(o, g.ny);
    put(o, g.dx);
    put(o, g.x_min);
    put(o, g.y_min);
    put_text(o, g.crs_wkt);
    put_text(o, g.crs_name);
    o.write(reinterpret_cast<const char*>(g.z.data()), std::streamsize(g.z.size() * sizeof(double)));
    o.write(reinterpret_cast<const char*>(g.outside.data()), std::streamsize(g.outside.size()));
    put_text(o, r.source_crs);
    for (double v : {r.source_resolution_m, r.slope_mean_deg, r.slope_max_deg, r.slope_p90_deg, r.z_min, r.z_max}) put(o, v);
    put(o, std::uint8_t(r.used_aoi));
    put(o, std::int64_t(r.cells_without_data));
    put(o, std::int64_t(r.cells_outside_area));
    if (!o.flush()) {
      std::remove(tmp.c_str());
      return;  // a cache that cannot be written is no error: the next run prepares the grid again
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) std::remove(tmp.c_str());
}

bool load_grid(const std::string& path, Grid& g, DemReport& r) {
  std::ifstream i(path, std::ios::binary);
  char magic[sizeof kMagic - 1];
  if (!i.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof magic) != 0) return false;
  Grid out;
  if (!get(i, out.nx) || !get(i, out.ny) || !get(i, out.dx) || !get(i, out.x_min) || !get(i, out.y_min) || out.nx <= 0 || out.ny <= 0 ||
      !get_text(i, out.crs_wkt) || !get_text(i, out.crs_name))
    return false;
  out.z.resize(out.cells());
  out.outside.resize(out.cells());
  if (!i.read(reinterpret_cast<char*>(out.z.data()), std::streamsize(out.z.size() * sizeof(double))) ||
      !i.read(reinterpret_cast<char*>(out.outside.data()), std::streamsize(out.outside.size())))
    return false;
  DemReport rep;
  std::uint8_t aoi = 0;
  std::int64_t without = 0, outside = 0;
  if (!get_text(i, rep.source_crs)) return false;
  for (double* v : {&rep.source_resolution_m, &rep.slope_mean_deg, &rep.slope_max_deg, &rep.slope_p90_deg, &rep.z_min, &rep.z_max})
    if (!get(i, *v)) return false;
  if (!get(i, aoi) || !get(i, without) || !get(i, outside)) return false;
  rep.used_aoi = aoi != 0;
  rep.cells_without_data = long(without);
  rep.cells_outside_area = long(outside);
  if (i.peek() != EOF) return false;
  g = std::move(out);
  r = rep;
  return true;
}

}  // namespace runout::terrain
