#pragma once
// The finite-volume operators the VOF equations are written with (OpenFOAM's fvc): face
// interpolation, the velocity-gradient tensor and the strain rate, the cells' faces, a pressure
// carried hydrostatically to a face, and the reconstruction of a cell vector from face values (the
// Gauss gradient in grad.hpp).
#include <array>
#include <cmath>
#include <span>

#include "engine/vof/fv/field.hpp"
#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

/// A 2x2 (plane) or 3x3 velocity gradient, row i = d/dx_i.
struct Tensor {
  double g[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
};

inline double comp(const Vec& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }
inline void add_comp(Vec& v, int i, double a) { (i == 0 ? v.x : i == 1 ? v.y : v.z) += a; }
inline double& comp_ref(Vec& v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

inline bool internal(const Mesh& m, int f) { return f < m.n_internal; }
/// The unit normal of face f (out of its owner).
inline Vec unit_normal(const Mesh& m, int f) { return (1.0 / m.magSf[f]) * m.Sf[f]; }
/// The cell across internal face f from cell c.
inline int across(const Mesh& m, int f, int c) { return m.owner[f] == c ? m.neighbour[f] : m.owner[f]; }

/// Linear interpolation of a cell field to internal face f (fvc::interpolate).
template <class T>
T interpolate(const Mesh& m, int f, const CellField<T>& x) {
  const double w = m.weight[f];
  return w * x[m.owner[f]] + (1 - w) * x[m.neighbour[f]];
}
/// The same, or the owner's value on a boundary face.
template <class T>
T interpolate_or_owner(const Mesh& m, int f, const CellField<T>& x) {
  return internal(m, f) ? interpolate(m, f, x) : x[m.owner[f]];
}

/// |strain rate| = sqrt(2 D:D), D the symmetric part of the velocity gradient (OpenFOAM's
/// strainRate(), sqrt(2) |symm(grad U)|).
inline double strain_rate(const Tensor& gr) {
  const auto& g = gr.g;
  double dd = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double d = 0.5 * (g[i][j] + g[j][i]);
      dd += d * d;
    }
  return std::sqrt(2 * dd);
}

/// The faces of each cell in ascending order, stored flat.
struct CellFaces {
  std::vector<int> start, face_list;
  void build(const Mesh& m);
  std::span<const int> operator[](int c) const {
    return {face_list.data() + start[c], std::size_t(start[std::size_t(c) + 1] - start[c])};
  }
};

/// A pressure p carried hydrostatically from cell c to face f, p + rho (ghf - gh) (gh = g.x at the
/// cell centres, ghf at the face centres): the face value of p where p_rgh has zero gradient.
inline double carried_hydrostatically(double p_c, double rho_c, double gh_c, double ghf_f) { return p_c + rho_c * (ghf_f - gh_c); }

/// fvc::reconstruct: the cell vector whose face projections best match face values q, from the sum
/// of q Sf over the cell's faces (the inverse of sum Sf Sf / |Sf| per cell).
class Reconstruction {
 public:
  void build(const Mesh& m, const CellFaces& cell_faces, int dims);
  Vec operator()(int c, const Vec& r) const {
    const auto& T = inv_[c];
    return {T[0] * r.x + T[1] * r.y + T[2] * r.z, T[1] * r.x + T[3] * r.y + T[4] * r.z, T[2] * r.x + T[4] * r.y + T[5] * r.z};
  }

 private:
  CellField<std::array<double, 6>> inv_;  // xx, xy, xz, yy, yz, zz
};

}  // namespace runout::engine::vof
