#include "engine/vof/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace runout::engine::vof {

const Patch& Mesh::patch(const std::string& name) const {
  const int k = patch_index(name);
  if (k < 0) throw std::invalid_argument("mesh: no patch '" + name + "'");
  return patches[k];
}

int Mesh::patch_index(const std::string& name) const {
  for (std::size_t k = 0; k < patches.size(); ++k)
    if (patches[k].name == name) return int(k);
  return -1;
}

double Mesh::mean_cell_size() const {
  double sum = 0;
  for (double v : volume) sum += v;
  return std::cbrt(sum / cells());
}

void Mesh::finish() {
  const int nf = faces();
  magSf.assign(nf, 0);
  delta_coeff.assign(nf, 0);
  weight.assign(nf, 1);
  non_orth.assign(nf, Vec{});
  for (int f = 0; f < nf; ++f) {
    const std::size_t k = std::size_t(f);
    magSf[k] = norm(Sf[k]);
    const Vec n = (1.0 / magSf[k]) * Sf[k];
    const Vec cp = centre[owner[k]];
    if (f < n_internal) {
      const Vec cn = centre[neighbour[k]];
      delta_coeff[k] = 1.0 / std::abs(dot(cn - cp, n));
      non_orth[k] = Sf[k] - (magSf[k] * delta_coeff[k]) * (cn - cp);
      const double dp = std::abs(dot(Cf[k] - cp, n)), dn = std::abs(dot(cn - Cf[k], n));
      weight[k] = dn / (dp + dn);
    } else {
      delta_coeff[k] = 1.0 / std::abs(dot(Cf[k] - cp, n));
      non_orth[k] = Sf[k] - (magSf[k] * delta_coeff[k]) * (Cf[k] - cp);
    }
  }
  // Every cell must be closed: the sum of its outward area vectors vanishes.
  std::vector<Vec> sum(static_cast<std::size_t>(cells()));
  for (int f = 0; f < nf; ++f) {
    sum[owner[f]] = sum[owner[f]] + Sf[f];
    if (f < n_internal)
      sum[neighbour[f]] = sum[neighbour[f]] - Sf[f];
  }
  for (int c = 0; c < cells(); ++c) {
    const double scale = std::cbrt(volume[c]) * std::cbrt(volume[c]);
    // Plane meshes have no front/back faces: only x and y must close.
    const Vec s = sum[c];
    const double open = thickness > 0 ? std::hypot(s.x, s.y) : norm(s);
    if (open > 1e-9 * std::max(scale, 1e-30)) throw std::logic_error("mesh: cell " + std::to_string(c) + " is not closed");
  }
}

namespace {
struct BFace {  // a boundary face while a block is being built
  int owner;
  Vec Sf, Cf;
};

// Append boundary faces as the patch `name` (none: no patch).
void append_patch(Mesh& m, const std::string& name, const std::vector<BFace>& fs) {
  if (fs.empty()) return;
  m.patches.push_back({name, m.faces(), int(fs.size())});
  for (const auto& f : fs) {
    m.owner.push_back(f.owner);
    m.Sf.push_back(f.Sf);
    m.Cf.push_back(f.Cf);
  }
}

// Node coordinates of a graded direction: cell sizes h_k = h0 r^k with r^(n-1) = grading.
std::vector<double> graded_nodes(double a, double b, int n, double grading) {
  std::vector<double> v(std::size_t(n) + 1);
  const double r = n > 1 ? std::pow(grading, 1.0 / (n - 1)) : 1.0;
  double total = 0, h = 1;
  for (int k = 0; k < n; ++k, h *= r) total += h;
  h = (b - a) / total;
  v[0] = a;
  double y = a;
  for (int k = 0; k < n; ++k, h *= r) v[std::size_t(k) + 1] = (y += h);
  v[n] = b;
  return v;
}
}  // namespace

Mesh block_mesh(const BlockSpec& s) {
  if (s.nx < 1 || s.ny < 1 || !(s.x1 > s.x0) || !(s.y1 > s.y0) || !(s.thickness > 0) || !(s.y_grading > 0))
    throw std::invalid_argument("block mesh: needs x1 > x0, y1 > y0, nx, ny >= 1, thickness > 0, y_grading > 0");
  const auto xs = graded_nodes(s.x0, s.x1, s.nx, 1.0), ys = graded_nodes(s.y0, s.y1, s.ny, s.y_grading);
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
      const double cx = 0.5 * (xs[i] + xs[std::size_t(i) + 1]), cy = 0.5 * (ys[j] + ys[std::size_t(j) + 1]);
      if (inside(cx, cy) || (s.blocked_if && s.blocked_if(Vec{cx, cy, 0}))) continue;
      id[std::size_t(j) * std::size_t(s.nx) + std::size_t(i)] = m.cells();
      m.centre.push_back({cx, cy, 0});
      m.volume.push_back((xs[std::size_t(i) + 1] - xs[i]) * (ys[std::size_t(j) + 1] - ys[j]) * s.thickness);
    }
  if (m.cells() == 0) throw std::invalid_argument("block mesh: every cell is blocked");
  auto cell = [&](int i, int j) {
    return (i < 0 || j < 0 || i >= s.nx || j >= s.ny) ? -1 : id[std::size_t(j) * std::size_t(s.nx) + std::size_t(i)];
  };
  std::vector<BFace> left, right, bottom, top, obstacle;
  // Faces normal to x: between (i-1, j) and (i, j).
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i <= s.nx; ++i) {
      const double dy = ys[std::size_t(j) + 1] - ys[j];
      const Vec c{xs[i], 0.5 * (ys[j] + ys[std::size_t(j) + 1]), 0};
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
      const double dx = xs[std::size_t(i) + 1] - xs[i];
      const Vec c{0.5 * (xs[i] + xs[std::size_t(i) + 1]), ys[j], 0};
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
  append_patch(m, "bottom", bottom);
  append_patch(m, "right", right);
  append_patch(m, "top", top);
  append_patch(m, "left", left);
  append_patch(m, "obstacle", obstacle);
  m.finish();
  return m;
}


Mesh block_mesh_3d(const Block3Spec& s) {
  if (s.nx < 1 || s.ny < 1 || s.nz < 1 || !(s.x1 > s.x0) || !(s.y1 > s.y0) || !(s.z1 > s.z0) || !(s.y_grading > 0))
    throw std::invalid_argument("block mesh: needs x1 > x0, y1 > y0, z1 > z0, nx, ny, nz >= 1, y_grading > 0");
  const auto xs = graded_nodes(s.x0, s.x1, s.nx, 1.0), ys = graded_nodes(s.y0, s.y1, s.ny, s.y_grading),
             zs = graded_nodes(s.z0, s.z1, s.nz, 1.0);
  Mesh m;
  m.thickness = 0;
  const std::size_t NX = std::size_t(s.nx), NY = std::size_t(s.ny), NZ = std::size_t(s.nz);
  std::vector<int> id(NX * NY * NZ, -1);
  auto at = [&](std::size_t i, std::size_t j, std::size_t k) { return (k * NY + j) * NX + i; };
  for (std::size_t k = 0; k < NZ; ++k)
    for (std::size_t j = 0; j < NY; ++j)
      for (std::size_t i = 0; i < NX; ++i) {
        const Vec c{0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1]), 0.5 * (zs[k] + zs[k + 1])};
        if (s.blocked && s.blocked(c)) continue;
        id[at(i, j, k)] = m.cells();
        m.centre.push_back(c);
        m.volume.push_back((xs[i + 1] - xs[i]) * (ys[j + 1] - ys[j]) * (zs[k + 1] - zs[k]));
      }
  if (m.cells() == 0) throw std::invalid_argument("block mesh: every cell is blocked");
  auto cell = [&](long i, long j, long k) {
    if (i < 0 || j < 0 || k < 0 || i >= s.nx || j >= s.ny || k >= s.nz) return -1;
    return id[at(std::size_t(i), std::size_t(j), std::size_t(k))];
  };
  std::map<std::string, std::vector<BFace>> bnd;
  // Faces normal to direction d between cell (.., n-1, ..) and (.., n, ..) along d.
  for (int d = 0; d < 3; ++d) {
    const long ni = s.nx + (d == 0), nj = s.ny + (d == 1), nk = s.nz + (d == 2);
    const char* lo = d == 0 ? "left" : d == 1 ? "bottom" : "back";
    const char* hi = d == 0 ? "right" : d == 1 ? "top" : "front";
    for (long k = 0; k < nk; ++k)
      for (long j = 0; j < nj; ++j)
        for (long i = 0; i < ni; ++i) {
          const long ia = i - (d == 0), ja = j - (d == 1), ka = k - (d == 2);
          const int a = cell(ia, ja, ka), b = cell(i, j, k);
          if (a < 0 && b < 0) continue;
          const auto I = std::size_t(i), J = std::size_t(j), K = std::size_t(k);
          const double ex = d == 0 ? 0 : xs[I + 1] - xs[I], ey = d == 1 ? 0 : ys[J + 1] - ys[J], ez = d == 2 ? 0 : zs[K + 1] - zs[K];
          const Vec c{d == 0 ? xs[I] : 0.5 * (xs[I] + xs[I + 1]), d == 1 ? ys[J] : 0.5 * (ys[J] + ys[J + 1]),
                      d == 2 ? zs[K] : 0.5 * (zs[K] + zs[K + 1])};
          const double area = d == 0 ? ey * ez : d == 1 ? ex * ez : ex * ey;
          Vec S{d == 0 ? area : 0, d == 1 ? area : 0, d == 2 ? area : 0};
          if (a >= 0 && b >= 0) {
            m.owner.push_back(a);
            m.neighbour.push_back(b);
            m.Sf.push_back(S);
            m.Cf.push_back(c);
          } else if (a >= 0) {
            const bool edge = (d == 0 ? i : d == 1 ? j : k) == (d == 0 ? s.nx : d == 1 ? s.ny : s.nz);
            bnd[edge ? hi : "obstacle"].push_back({a, S, c});
          } else {
            const bool edge = (d == 0 ? i : d == 1 ? j : k) == 0;
            bnd[edge ? lo : "obstacle"].push_back({b, (-1.0) * S, c});
          }
        }
  }
  m.n_internal = int(m.owner.size());
  for (const char* name : {"bottom", "right", "top", "left", "back", "front", "obstacle"}) append_patch(m, name, bnd[name]);
  m.finish();
  return m;
}

Mesh structured_hex_mesh(const HexGridSpec& s) {
  if (s.ni < 1 || s.nj < 1 || s.nk < 1 || !s.node) throw std::invalid_argument("hex mesh: needs ni, nj, nk >= 1 and node positions");
  const std::size_t NI = std::size_t(s.ni), NJ = std::size_t(s.nj), NK = std::size_t(s.nk);
  std::vector<Vec> X((NI + 1) * (NJ + 1) * (NK + 1));
  auto nid = [&](std::size_t i, std::size_t j, std::size_t k) { return (k * (NJ + 1) + j) * (NI + 1) + i; };
  for (std::size_t k = 0; k <= NK; ++k)
    for (std::size_t j = 0; j <= NJ; ++j)
      for (std::size_t i = 0; i <= NI; ++i) X[nid(i, j, k)] = s.node(int(i), int(j), int(k));
  Mesh m;
  m.thickness = 0;
  // Kept cells numbered i fastest, then j, then k (with nothing blocked: cell (i, j, k) is (k nj + j) ni + i).
  std::vector<int> id(NI * NJ * NK, -1);
  int kept = 0;
  for (std::size_t k = 0; k < NK; ++k)
    for (std::size_t j = 0; j < NJ; ++j)
      for (std::size_t i = 0; i < NI; ++i) {
        if (s.blocked && s.blocked(int(i), int(j), int(k))) continue;
        Vec c;
        for (int q = 0; q < 8; ++q) c = c + X[nid(i + (q & 1), j + ((q >> 1) & 1), k + ((q >> 2) & 1))];
        id[(k * NJ + j) * NI + i] = kept++;
        m.centre.push_back(0.125 * c);
      }
  if (kept == 0) throw std::invalid_argument("hex mesh: every cell is blocked");
  m.volume.assign(std::size_t(kept), 0.0);
  auto cid = [&](long i, long j, long k) {
    if (i < 0 || j < 0 || k < 0 || i >= s.ni || j >= s.nj || k >= s.nk) return -1;
    return id[(std::size_t(k) * NJ + std::size_t(j)) * NI + std::size_t(i)];
  };
  auto cross = [](Vec a, Vec b) { return Vec{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; };
  const auto& names = s.patch_names;  // left, right, bottom, top, back, front, blocked
  std::map<std::string, std::vector<BFace>> bnd;
  // Faces normal to grid direction d, between cell (.., n-1, ..) and (.., n, ..) along d.
  for (int d = 0; d < 3; ++d) {
    const long ni = s.ni + (d == 0), nj = s.nj + (d == 1), nk = s.nk + (d == 2), n_d = d == 0 ? s.ni : d == 1 ? s.nj : s.nk;
    const std::string& lo = names[std::size_t(2 * d)];
    const std::string& hi = names[std::size_t(2 * d + 1)];
    for (long k = 0; k < nk; ++k)
      for (long j = 0; j < nj; ++j)
        for (long i = 0; i < ni; ++i) {
          const int a = cid(i - (d == 0), j - (d == 1), k - (d == 2)), b = cid(i, j, k);
          if (a < 0 && b < 0) continue;
          // The face's four nodes: the node (i, j, k) and its neighbours in the two other directions.
          const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
          auto corner = [&](int u, int v) {
            long I = i, J = j, K = k;
            (e1 == 0 ? I : e1 == 1 ? J : K) += u;
            (e2 == 0 ? I : e2 == 1 ? J : K) += v;
            return X[nid(std::size_t(I), std::size_t(J), std::size_t(K))];
          };
          const Vec p00 = corner(0, 0), p10 = corner(1, 0), p11 = corner(1, 1), p01 = corner(0, 1);
          Vec S = 0.5 * cross(p11 - p00, p01 - p10);
          const Vec C = 0.25 * (p00 + p10 + p11 + p01);
          // Orient from a to b (or out of the one cell on the boundary).
          const Vec along = a >= 0 && b >= 0 ? m.centre[b] - m.centre[a]
                            : a >= 0         ? C - m.centre[a]
                                             : m.centre[b] - C;
          if (dot(S, along) < 0) S = (-1.0) * S;
          const long n_here = d == 0 ? i : d == 1 ? j : k;
          if (a >= 0 && b >= 0) {
            m.owner.push_back(a);
            m.neighbour.push_back(b);
            m.Sf.push_back(S);
            m.Cf.push_back(C);
          } else if (a >= 0) {
            bnd[n_here == n_d ? hi : names[6]].push_back({a, S, C});
          } else {
            bnd[n_here == 0 ? lo : names[6]].push_back({b, (-1.0) * S, C});
          }
        }
  }
  m.n_internal = int(m.owner.size());
  // Patches in the order bottom, right, top, left, back, front, blocked; equal names make one patch.
  std::vector<std::string> order;
  for (std::size_t q : {2, 1, 3, 0, 4, 5, 6})
    if (std::find(order.begin(), order.end(), names[q]) == order.end()) order.push_back(names[q]);
  for (const auto& name : order) append_patch(m, name, bnd[name]);
  // Volumes by the divergence theorem: V = sum over the cell's faces of (Cf - c) . Sf / 3.
  for (int f = 0; f < m.faces(); ++f) {
    const int o = m.owner[f];
    m.volume[o] += dot(m.Cf[f] - m.centre[o], m.Sf[f]) / 3;
    if (f < m.n_internal) {
      const int nb = m.neighbour[f];
      m.volume[nb] -= dot(m.Cf[f] - m.centre[nb], m.Sf[f]) / 3;
    }
  }
  for (int c = 0; c < m.cells(); ++c)
    if (!(m.volume[c] > 0)) throw std::invalid_argument("hex mesh: cell " + std::to_string(c) + " is inverted or flat (volume " + std::to_string(m.volume[c]) + ")");
  m.finish();
  return m;
}

}  // namespace runout::engine::vof
