#pragma once
// A finite-volume matrix over the mesh's cells (OpenFOAM's fvMatrix), in the form
//   A_P psi_P - sum_nb c_nb psi_nb = source_P,
// with A_P the diagonal, c_nb the neighbour coefficients of the internal faces (upper: the
// neighbour's in the owner's row; lower: the owner's in the neighbour's row) and the source. The
// momentum matrix is an FvMatrix<Vec> (both components share it), the pressure equation's
// Laplacian an FvMatrix<double> (symmetric: upper only).
#include <vector>

#include "engine/vof/fv/field.hpp"
#include "engine/vof/fv/ops.hpp"
#include "engine/vof/fv/parallel.hpp"
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

  /// H(psi) = source + sum_nb c_nb psi_nb over `cells`, from their internal faces marked in
  /// `face_in` (1: the face takes part), into `out` (interFoam's UEqn.H()). Per cell over its faces
  /// in ascending order, over the OpenMP threads (fv/parallel.hpp).
  void H(const Mesh& m, const CellFaces& cf, const std::vector<char>& face_in, const CellField<T>& psi, const std::vector<int>& cells,
         CellField<T>& out) const {
    parallel_each(cells, [&](int c) {
      T sum = source[c];
      for (int f : cf[c]) {
        if (f >= m.n_internal || !face_in[f]) continue;
        sum = m.owner[f] == c ? sum + upper[f] * psi[m.neighbour[f]] : sum + lower[f] * psi[m.owner[f]];
      }
      out[c] = sum;
    });
  }

  /// H1 = sum_nb c_nb (the neighbour coefficients' sum per cell, SIMPLEC's), into `out`, as H.
  void H1(const Mesh& m, const CellFaces& cf, const std::vector<char>& face_in, const std::vector<int>& cells, CellField<double>& out) const {
    parallel_each(cells, [&](int c) {
      double sum = 0;
      for (int f : cf[c]) {
        if (f >= m.n_internal || !face_in[f]) continue;
        sum += m.owner[f] == c ? upper[f] : lower[f];
      }
      out[c] = sum;
    });
  }

  /// The flux the off-diagonal part carries through internal face f (symmetric matrices such as a
  /// Laplacian): -c (psi_N - psi_P), out of the owner (interFoam's pEqn.flux()).
  double flux(const Mesh& m, int f, const CellField<double>& psi) const { return -upper[f] * (psi[m.neighbour[f]] - psi[m.owner[f]]); }
  /// The same through a face to a fixed value psi_out outside, out of the cell a inside.
  double flux_out(int f, double psi_a, double psi_out) const { return -upper[f] * (psi_out - psi_a); }
};

}  // namespace runout::engine::vof
