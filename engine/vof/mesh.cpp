#include "engine/vof/mesh.hpp"

#include <algorithm>
#include <stdexcept>

namespace runout::engine::vof {

const Patch& Mesh::patch(const std::string& name) const {
  const int k = patch_index(name);
  if (k < 0) throw std::invalid_argument("mesh: no patch '" + name + "'");
  return patches[std::size_t(k)];
}

int Mesh::patch_index(const std::string& name) const {
  for (std::size_t k = 0; k < patches.size(); ++k)
    if (patches[k].name == name) return int(k);
  return -1;
}

void Mesh::finish() {
  const int nf = faces();
  magSf.assign(std::size_t(nf), 0);
  delta_coeff.assign(std::size_t(nf), 0);
  weight.assign(std::size_t(nf), 1);
  for (int f = 0; f < nf; ++f) {
    const std::size_t k = std::size_t(f);
    magSf[k] = norm(Sf[k]);
    const Vec n = (1.0 / magSf[k]) * Sf[k];
    const Vec cp = centre[std::size_t(owner[k])];
    if (f < n_internal) {
      const Vec cn = centre[std::size_t(neighbour[k])];
      delta_coeff[k] = 1.0 / std::abs(dot(cn - cp, n));
      const double dp = std::abs(dot(Cf[k] - cp, n)), dn = std::abs(dot(cn - Cf[k], n));
      weight[k] = dn / (dp + dn);
    } else {
      delta_coeff[k] = 1.0 / std::abs(dot(Cf[k] - cp, n));
    }
  }
  // Every cell must be closed: the sum of its outward area vectors vanishes.
  std::vector<Vec> sum(static_cast<std::size_t>(cells()));
  for (int f = 0; f < nf; ++f) {
    sum[std::size_t(owner[std::size_t(f)])] = sum[std::size_t(owner[std::size_t(f)])] + Sf[std::size_t(f)];
    if (f < n_internal)
      sum[std::size_t(neighbour[std::size_t(f)])] = sum[std::size_t(neighbour[std::size_t(f)])] - Sf[std::size_t(f)];
  }
  for (int c = 0; c < cells(); ++c) {
    const double scale = std::cbrt(volume[std::size_t(c)]) * std::cbrt(volume[std::size_t(c)]);
    // Plane meshes have no front/back faces: only x and y must close.
    const Vec s = sum[std::size_t(c)];
    const double open = thickness > 0 ? std::hypot(s.x, s.y) : norm(s);
    if (open > 1e-9 * std::max(scale, 1e-30)) throw std::logic_error("mesh: cell " + std::to_string(c) + " is not closed");
  }
}

Mesh block_mesh(const BlockSpec& s) {
  if (s.nx < 1 || s.ny < 1 || !(s.x1 > s.x0) || !(s.y1 > s.y0) || !(s.thickness > 0) || !(s.y_grading > 0))
    throw std::invalid_argument("block mesh: needs x1 > x0, y1 > y0, nx, ny >= 1, thickness > 0, y_grading > 0");
  // Node coordinates.
  std::vector<double> xs(std::size_t(s.nx) + 1), ys(std::size_t(s.ny) + 1);
  for (int i = 0; i <= s.nx; ++i) xs[std::size_t(i)] = s.x0 + (s.x1 - s.x0) * i / s.nx;
  {
    // Geometric cell heights h_k = h0 r^k with r^(ny-1) = grading.
    const double r = s.ny > 1 ? std::pow(s.y_grading, 1.0 / (s.ny - 1)) : 1.0;
    double total = 0, h = 1;
    for (int k = 0; k < s.ny; ++k, h *= r) total += h;
    double y = s.y0;
    h = (s.y1 - s.y0) / total;
    ys[0] = s.y0;
    for (int k = 0; k < s.ny; ++k, h *= r) ys[std::size_t(k) + 1] = (y += h);
    ys[std::size_t(s.ny)] = s.y1;
  }
  auto inside = [&](double x, double y) {
    const auto& p = s.blocked;
    if (p.size() < 3) return false;
    bool in = false;
    for (std::size_t a = 0, b = p.size() - 1; a < p.size(); b = a++) {
      if ((p[a][1] > y) != (p[b][1] > y) && x < (p[b][0] - p[a][0]) * (y - p[a][1]) / (p[b][1] - p[a][1]) + p[a][0]) in = !in;
    }
    return in;
  };
  Mesh m;
  m.thickness = s.thickness;
  std::vector<int> id(std::size_t(s.nx) * std::size_t(s.ny), -1);
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i < s.nx; ++i) {
      const double cx = 0.5 * (xs[std::size_t(i)] + xs[std::size_t(i) + 1]), cy = 0.5 * (ys[std::size_t(j)] + ys[std::size_t(j) + 1]);
      if (inside(cx, cy)) continue;
      id[std::size_t(j) * std::size_t(s.nx) + std::size_t(i)] = m.cells();
      m.centre.push_back({cx, cy, 0});
      m.volume.push_back((xs[std::size_t(i) + 1] - xs[std::size_t(i)]) * (ys[std::size_t(j) + 1] - ys[std::size_t(j)]) * s.thickness);
    }
  if (m.cells() == 0) throw std::invalid_argument("block mesh: every cell is blocked");
  auto cell = [&](int i, int j) {
    return (i < 0 || j < 0 || i >= s.nx || j >= s.ny) ? -1 : id[std::size_t(j) * std::size_t(s.nx) + std::size_t(i)];
  };
  struct BFace {
    int owner;
    Vec Sf, Cf;
  };
  std::vector<BFace> left, right, bottom, top, obstacle;
  // Faces normal to x: between (i-1, j) and (i, j).
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i <= s.nx; ++i) {
      const double dy = ys[std::size_t(j) + 1] - ys[std::size_t(j)];
      const Vec c{xs[std::size_t(i)], 0.5 * (ys[std::size_t(j)] + ys[std::size_t(j) + 1]), 0};
      const int a = cell(i - 1, j), b = cell(i, j);
      if (a >= 0 && b >= 0) {
        m.owner.push_back(a);
        m.neighbour.push_back(b);
        m.Sf.push_back({dy * s.thickness, 0, 0});
        m.Cf.push_back(c);
      } else if (a >= 0) {
        (i == s.nx ? right : obstacle).push_back({a, {dy * s.thickness, 0, 0}, c});
      } else if (b >= 0) {
        (i == 0 ? left : obstacle).push_back({b, {-dy * s.thickness, 0, 0}, c});
      }
    }
  // Faces normal to y: between (i, j-1) and (i, j).
  for (int j = 0; j <= s.ny; ++j)
    for (int i = 0; i < s.nx; ++i) {
      const double dx = xs[std::size_t(i) + 1] - xs[std::size_t(i)];
      const Vec c{0.5 * (xs[std::size_t(i)] + xs[std::size_t(i) + 1]), ys[std::size_t(j)], 0};
      const int a = cell(i, j - 1), b = cell(i, j);
      if (a >= 0 && b >= 0) {
        m.owner.push_back(a);
        m.neighbour.push_back(b);
        m.Sf.push_back({0, dx * s.thickness, 0});
        m.Cf.push_back(c);
      } else if (a >= 0) {
        (j == s.ny ? top : obstacle).push_back({a, {0, dx * s.thickness, 0}, c});
      } else if (b >= 0) {
        (j == 0 ? bottom : obstacle).push_back({b, {0, -dx * s.thickness, 0}, c});
      }
    }
  m.n_internal = int(m.owner.size());
  auto add = [&](const std::string& name, const std::vector<BFace>& fs) {
    if (fs.empty()) return;
    m.patches.push_back({name, m.faces(), int(fs.size())});
    for (const auto& f : fs) {
      m.owner.push_back(f.owner);
      m.Sf.push_back(f.Sf);
      m.Cf.push_back(f.Cf);
    }
  };
  add("bottom", bottom);
  add("right", right);
  add("top", top);
  add("left", left);
  add("obstacle", obstacle);
  m.finish();
  return m;
}

}  // namespace runout::engine::vof
