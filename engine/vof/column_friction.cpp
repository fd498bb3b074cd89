#include "engine/vof/column_friction.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/vof/active_region.hpp"
#include "engine/vof/error.hpp"
#include "engine/vof/fields.hpp"
#include "engine/vof/hydrostatics.hpp"

namespace runout::engine::vof {

namespace {

double quadratic(const Tensor& K, const Vec& u) {
  double s = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s += comp(u, i) * K.g[i][j] * comp(u, j);
  return s;
}

}  // namespace

void check_columns(const Mesh& m, const MeshColumns& c) {
  const int n = c.columns();
  if (int(c.start.size()) != n + 1 || c.start.front() != 0 || c.start.back() != int(c.cells.size()))
    throw VofError("column friction: the columns' offsets do not match their cells");
  if (!c.curvature.empty() && int(c.curvature.size()) != n) throw VofError("column friction: one curvature per column, or none");
  std::vector<char> seen(std::size_t(m.faces()), 0);
  for (int k = 0; k < n; ++k) {
    const int f = c.bed_face[std::size_t(k)];
    if (f < m.n_internal || f >= m.faces() || seen[std::size_t(f)]++)
      throw VofError("column friction: column " + std::to_string(k) + "'s bed face is not a boundary face of its own");
    if (c.start[std::size_t(k) + 1] <= c.start[std::size_t(k)] || c.cells[std::size_t(c.start[std::size_t(k)])] != m.owner[std::size_t(f)])
      throw VofError("column friction: column " + std::to_string(k) + " does not start at its bed face's cell");
    for (int i = c.start[std::size_t(k)]; i < c.start[std::size_t(k) + 1]; ++i)
      if (c.cells[std::size_t(i)] < 0 || c.cells[std::size_t(i)] >= m.cells())
        throw VofError("column friction: column " + std::to_string(k) + " names a cell outside the mesh");
  }
}

MeshColumns columns_above(const Mesh& m, const std::vector<int>& bed_faces) {
  std::vector<std::vector<int>> faces_of(std::size_t(m.cells()));
  for (int f = 0; f < m.faces(); ++f) {
    faces_of[std::size_t(m.owner[std::size_t(f)])].push_back(f);
    if (f < m.n_internal) faces_of[std::size_t(m.neighbour[std::size_t(f)])].push_back(f);
  }
  MeshColumns out;
  out.start.push_back(0);
  std::vector<char> taken(std::size_t(m.cells()), 0);
  for (int f : bed_faces) {
    if (f < m.n_internal || f >= m.faces()) throw VofError("column friction: face " + std::to_string(f) + " is not a boundary face");
    const Vec up = (-1.0 / m.magSf[std::size_t(f)]) * m.Sf[std::size_t(f)];  // into the domain
    out.bed_face.push_back(f);
    int c = m.owner[std::size_t(f)], entry = f;
    while (true) {
      if (taken[std::size_t(c)]++) throw VofError("column friction: cell " + std::to_string(c) + " lies in two columns");
      out.cells.push_back(c);
      int best = -1;
      double best_cos = std::cos(25 * 3.14159265358979323846 / 180);
      for (int g : faces_of[std::size_t(c)]) {
        if (g == entry) continue;
        const double sign = m.owner[std::size_t(g)] == c ? 1.0 : -1.0;  // the face's normal out of c
        const double cosine = sign * dot(m.Sf[std::size_t(g)], up) / m.magSf[std::size_t(g)];
        if (cosine > best_cos) {
          best_cos = cosine;
          best = g;
        }
      }
      if (best < 0) throw VofError("column friction: no face of cell " + std::to_string(c) + " faces away from bed face " + std::to_string(f));
      if (best >= m.n_internal) break;  // the top of the column
      entry = best;
      c = m.owner[std::size_t(best)] == c ? m.neighbour[std::size_t(best)] : m.owner[std::size_t(best)];
    }
    out.start.push_back(int(out.cells.size()));
  }
  return out;
}

BedLoad add_column_friction(const Mesh& m, const ColumnFrictionConfig& cf, double rho1, const Fields& F, const Hydrostatics& hs,
                            const ActiveRegion& region, FvMatrix<Vec>& UEqn, ColumnDrag& out) {
  const MeshColumns& cols = cf.columns;
  for (int c : region.halo) out.drag[c] = 0;
  const Vec g = hs.gravity();
  BedLoad load;
  for (int k = 0; k < cols.columns(); ++k) {
    const int b = cols.start[std::size_t(k)], e = cols.start[std::size_t(k) + 1];
    const int bed_cell = cols.cells[std::size_t(b)];
    if (!region.active(bed_cell)) continue;  // material lies within the region's layers of its cells
    const int f = cols.bed_face[std::size_t(k)];
    const Vec n = (1.0 / m.magSf[f]) * m.Sf[f];  // out of the domain, into the ground
    // The column's material and its velocity (volume-weighted).
    double material = 0, column_volume = 0;
    Vec um;
    for (int i = b; i < e; ++i) {
      const int c = cols.cells[std::size_t(i)];
      const double v = F.alpha[c] * m.volume[c];
      material += v;
      column_volume += m.volume[c];
      um = um + v * F.U[c];
    }
    // Round-off traces (down to denormal numbers, whose mean velocity overflows) carry no load.
    if (!(material > 1e-12 * column_volume)) continue;
    um = (1.0 / material) * um;
    const Vec ut = um - dot(um, n) * n;
    const double mass = rho1 * material;
    const double weight_n = mass * std::max(dot(g, n), 0.0);
    const double centripetal = cols.curvature.empty() ? 0.0 : mass * quadratic(cols.curvature[std::size_t(k)], ut);
    // The bed face's pressure counts with the material's share of the bed cell: the air's share of a
    // partly filled cell (whose pressure the material next to it sets) carries nothing.
    const double face = std::max(hs.wall_pressure(f, bed_cell), 0.0) * m.magSf[f] * F.alpha[bed_cell];
    // The friction's load: the weight's normal part and the centripetal load. The bed face's pressure
    // is reported beside it but not taken as a floor: as max(weight, face pressure) the friction and
    // the pressure it raises at the block's edges fed each other, and the 35 deg block ran away
    // (docs/design/vof.md).
    const double N = std::max(weight_n + centripetal, 0.0);
    load.weight_normal += weight_n;
    load.centripetal += centripetal;
    load.face_pressure += face;
    load.friction_load += N;
    ++load.columns;
    // Each cell's share of the force by its material; the drag per unit of material volume.
    const double per_volume = cf.tan_delta * N / (material * std::max(norm(ut), cf.creep_speed));
    for (int i = b; i < e; ++i) {
      const int c = cols.cells[std::size_t(i)];
      const double v = F.alpha[c] * m.volume[c];
      if (!(v > 0) || !region.active(c)) continue;
      const double drag = per_volume * v;
      UEqn.diag[c] += drag;  // the part on the bed-normal velocity given back: the force acts along the bed
      const Vec back = (drag * dot(F.U[c], n)) * n;
      UEqn.source[c] = UEqn.source[c] + back;
      out.drag[c] = drag;
      out.given_back[c] = back;
      out.normal[c] = n;
    }
  }
  return load;
}

}  // namespace runout::engine::vof
