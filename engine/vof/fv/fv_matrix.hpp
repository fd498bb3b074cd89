#pragma once
// A finite-volume matrix over the mesh's cells (OpenFOAM's fvMatrix), in the form
//   A_P psi_P - sum_nb c_nb psi_nb = source_P,
// with A_P the diagonal, c_nb the neighbour coefficients of the internal faces (upper: the
// neighbour's in the owner's row; lower: the owner's in the neighbour's row) and the source. The
// momentum matrix is an FvMatrix<Vec> (both components share it), the pressure equation's
// Laplacian an FvMatrix<double> (symmetric: upper only).
#include <vector>

#include "engine/vof/fv/field.hpp"
#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

template <class T>
struct FvMatrix {
  CellField<double> diag;
  FaceField<double> upper, lower;
  CellField<T> source;

  void resize(int cells, int faces) {
    diag.assign(cells, 0.0);
    source.assign(cells, T{});
    upper.assign(faces, 0.0);
    lower.assign(faces, 0.0);
  }

  /// The diagonal A (interFoam's UEqn.A(), per cell, not divided by the volume).
  const CellField<double>& A() const { return diag; }

  /// H(psi) = source + sum_nb c_nb psi_nb over `cells`, from the internal faces of `faces` (sorted:
  /// internal faces first), into `out` (interFoam's UEqn.H()).
  void H(const Mesh& m, const CellField<T>& psi, const std::vector<int>& cells, const std::vector<int>& faces, CellField<T>& out) const {
    for (int c : cells) out[c] = source[c];
    for (int f : faces) {
      if (f >= m.n_internal) break;
      const int o = m.owner[f], nb = m.neighbour[f];
      out[o] = out[o] + upper[f] * psi[nb];
      out[nb] = out[nb] + lower[f] * psi[o];
    }
  }

  /// H1 = sum_nb c_nb (the neighbour coefficients' sum per cell, SIMPLEC's), into `out`.
  void H1(const Mesh& m, const std::vector<int>& cells, const std::vector<int>& faces, CellField<double>& out) const {
    for (int c : cells) out[c] = 0;
    for (int f : faces) {
      if (f >= m.n_internal) break;
      out[m.owner[f]] += upper[f];
      out[m.neighbour[f]] += lower[f];
    }
  }

  /// The flux the off-diagonal part carries through internal face f (symmetric matrices such as a
  /// Laplacian): -c (psi_N - psi_P), out of the owner (interFoam's pEqn.flux()).
  double flux(const Mesh& m, int f, const CellField<double>& psi) const { return -upper[f] * (psi[m.neighbour[f]] - psi[m.owner[f]]); }
  /// The same through a face to a fixed value psi_out outside, out of the cell a inside.
  double flux_out(int f, double psi_a, double psi_out) const { return -upper[f] * (psi_out - psi_a); }
};

}  // namespace runout::engine::vof
