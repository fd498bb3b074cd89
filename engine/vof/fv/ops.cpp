#include "engine/vof/fv/ops.hpp"

#include "engine/vof/fv/grad.hpp"

namespace runout::engine::vof {

void gauss_gradient_hydrostatic(const Mesh& m, const CellFaces& cell_faces, const std::vector<int>& cells, const CellField<double>& p,
                                const CellField<double>& rho, const CellField<double>& gh, const FaceField<double>& ghf,
                                CellField<Vec>& out) {
  if (out.size() != std::size_t(m.cells())) out.assign(std::size_t(m.cells()), Vec{});
  const auto face_p = [&](int f, int c) {
    return internal(m, f) ? interpolate(m, f, p) : carried_hydrostatically(p[c], rho[c], gh[c], ghf[f]);
  };
  grad(m, cell_faces, cells, face_p, out);
}

void CellFaces::build(const Mesh& m) {
  const int nc = m.cells(), nf = m.faces();
  start.assign(std::size_t(nc) + 1, 0);
  for (int f = 0; f < nf; ++f) {
    ++start[std::size_t(m.owner[f]) + 1];
    if (f < m.n_internal) ++start[std::size_t(m.neighbour[f]) + 1];
  }
  for (int c = 0; c < nc; ++c) start[std::size_t(c) + 1] += start[c];
  face_list.assign(std::size_t(start[nc]), 0);
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int f = 0; f < nf; ++f) {
    face_list[next[m.owner[f]]++] = f;
    if (f < m.n_internal) face_list[next[m.neighbour[f]]++] = f;
  }
}

void Reconstruction::build(const Mesh& m, const CellFaces& cell_faces, int dims) {
  const int nc = m.cells();
  inv_.resize(nc);
  for (int c = 0; c < nc; ++c) {
    double t[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int f : cell_faces[c]) {
      const Vec& S = m.Sf[f];
      const double a = m.magSf[f];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t[i][j] += comp(S, i) * comp(S, j) / a;
    }
    if (dims == 2) {  // plane meshes have no front and back faces: invert the x-y block
      const double det = t[0][0] * t[1][1] - t[0][1] * t[0][1];
      inv_[c] = {t[1][1] / det, -t[0][1] / det, 0, t[0][0] / det, 0, 0};
    } else {
      const double a = t[0][0], b = t[0][1], cc = t[0][2], d = t[1][1], e = t[1][2], f = t[2][2];
      const double A = d * f - e * e, B = cc * e - b * f, C = b * e - cc * d;
      const double det = a * A + b * B + cc * C;
      inv_[c] = {A / det, B / det, C / det, (a * f - cc * cc) / det, (b * cc - a * e) / det, (a * d - b * b) / det};
    }
  }
}

}  // namespace runout::engine::vof
