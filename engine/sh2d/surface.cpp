// The surface geometry of the terrain and the conversions between normal and vertical depth.
#include <algorithm>
#include <cmath>

#include "engine/sh2d.hpp"

namespace runout::engine {

SurfaceGeometry SurfaceGeometry::from(const Terrain2D& t) {
  SurfaceGeometry s;
  const int nx = t.nx, ny = t.ny;
  const std::size_t n = t.cells();
  s.bx.assign(n, 0);
  s.by.assign(n, 0);
  s.hxx.assign(n, 0);
  s.hxy.assign(n, 0);
  s.hyy.assign(n, 0);
  s.c.assign(n, 1);
  auto z = [&](int i, int j) {
    i = std::clamp(i, 0, nx - 1);
    j = std::clamp(j, 0, ny - 1);
    return t.z[std::size_t(j) * nx + i];
  };
  // Centred differences inside, one-sided at the edges (second derivatives copied from inside).
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = std::size_t(j) * nx + i;
      const int il = std::max(i - 1, 0), ir = std::min(i + 1, nx - 1);
      const int jl = std::max(j - 1, 0), jr = std::min(j + 1, ny - 1);
      s.bx[k] = ir > il ? (z(ir, j) - z(il, j)) / ((ir - il) * t.dx) : 0.0;
      s.by[k] = jr > jl ? (z(i, jr) - z(i, jl)) / ((jr - jl) * t.dy) : 0.0;
      const int ic = std::clamp(i, 1, std::max(nx - 2, 0)), jc = std::clamp(j, 1, std::max(ny - 2, 0));
      if (nx >= 3) s.hxx[k] = (z(ic + 1, j) - 2 * z(ic, j) + z(ic - 1, j)) / (t.dx * t.dx);
      if (ny >= 3) s.hyy[k] = (z(i, jc + 1) - 2 * z(i, jc) + z(i, jc - 1)) / (t.dy * t.dy);
      if (nx >= 3 && ny >= 3)
        s.hxy[k] = (z(ic + 1, jc + 1) - z(ic + 1, jc - 1) - z(ic - 1, jc + 1) + z(ic - 1, jc - 1)) /
                   (4 * t.dx * t.dy);
      s.c[k] = 1.0 / std::sqrt(1.0 + s.bx[k] * s.bx[k] + s.by[k] * s.by[k]);
    }
  return s;
}

Sh2dState state_from_normal_depth(const Terrain2D& terrain, const std::vector<double>& h) {
  if (h.size() != terrain.cells()) throw std::invalid_argument("initial depth: size differs from the terrain grid");
  const auto geo = SurfaceGeometry::from(terrain);
  Sh2dState s;
  s.H.resize(h.size());
  s.HU.assign(h.size(), 0.0);
  s.HV.assign(h.size(), 0.0);
  for (std::size_t k = 0; k < h.size(); ++k) s.H[k] = h[k] / geo.c[k];
  return s;
}

std::vector<double> normal_depth(const Terrain2D& terrain, const Sh2dState& s) {
  const auto geo = SurfaceGeometry::from(terrain);
  std::vector<double> h(s.H.size());
  for (std::size_t k = 0; k < h.size(); ++k) h[k] = s.H[k] * geo.c[k];
  return h;
}

}  // namespace runout::engine
