#pragma once
// The cell-centred Gauss gradient (OpenFOAM's fvc::grad, Gauss) of a scalar or vector field, with the
// caller's face values: every gradient of the VOF equations is this one function.
#include <vector>

#include "engine/vof/fv/field.hpp"
#include "engine/vof/fv/ops.hpp"
#include "engine/vof/fv/parallel.hpp"
#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

/// The Gauss gradient's term of face f in cell c, per kind of field: a scalar's face value x_f adds
/// x_f Sf to a vector, a vector's adds the tensor Sf x_f (row i = d/dx_i); Sf points out of the
/// owner, so a neighbour takes the term's negative. Then the sum per cell volume.
inline void add_gauss_term(Vec& sum, double xf, const Vec& S, bool owner) { sum = owner ? sum + xf * S : sum - xf * S; }
inline void add_gauss_term(Tensor& sum, const Vec& xf, const Vec& S, bool owner) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double v = comp(S, i) * comp(xf, j);
      if (owner) sum.g[i][j] += v;
      else sum.g[i][j] -= v;
    }
}
inline void per_volume(Vec& sum, double V) { sum = (1.0 / V) * sum; }
inline void per_volume(Tensor& sum, double V) {
  for (auto& row : sum.g)
    for (double& v : row) v /= V;
}

/// Every face takes part in grad().
struct AllFaces {
  bool operator()(int) const { return true; }
};

/// fvc::grad, Gauss: per listed cell c, the sum of its faces' terms x_f Sf (add_gauss_term), divided
/// by its volume, into out[c] (a scalar field's gradient a Vec, a vector field's a Tensor). The
/// caller's face policy: face_value(f, c) gives the value on face f of cell c (interpolated on
/// internal faces, and on the boundary the caller's condition), and only the faces with
/// takes_part(f) are summed. Each cell from its own faces in ascending order, so any subset and any
/// order of cells, and any number of threads, give the same values.
template <class G, class FaceValue, class TakesPart = AllFaces>
void grad(const Mesh& m, const CellFaces& cell_faces, const std::vector<int>& cells, const FaceValue& face_value, CellField<G>& out,
          const TakesPart& takes_part = {}) {
  parallel_each(cells, [&](int c) {
    G sum{};
    for (int f : cell_faces[c]) {
      if (!takes_part(f)) continue;
      add_gauss_term(sum, face_value(f, c), m.Sf[f], m.owner[f] == c);
    }
    per_volume(sum, m.volume[c]);
    out[c] = sum;
  });
}

/// grad(p) for a pressure p whose boundary faces take the cell's value carried hydrostatically
/// (carried_hydrostatically): into out[c] for the listed cells only.
void gauss_gradient_hydrostatic(const Mesh& m, const CellFaces& cell_faces, const std::vector<int>& cells, const CellField<double>& p,
                                const CellField<double>& rho, const CellField<double>& gh, const FaceField<double>& ghf,
                                CellField<Vec>& out);

}  // namespace runout::engine::vof
