// The face fluxes of the depth-averaged 2D scheme: every face of a tile grown by one from the box's
// predicted values (the point kernels face_side and face_flux in kernels.hpp): a branch-free row
// kernel for faces between two cells of the domain, a general function for the domain's edges,
// cells outside it and inactive neighbours.
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "engine/sh2d/solver.hpp"

namespace runout::engine::sh2d_detail {
namespace {

// Face state of cell q on the side `half` (+0.5: its upper face, -0.5: its lower face) in face
// coordinates (normal, tangential): x faces use (U, V, Pxx), y faces (V, U, Pyy).
template <bool X>
FaceState side_state(const TileWork& w, std::size_t q, double half) {
  if constexpr (X)
    return face_side(w.Hp[q], w.sHx[q], w.Up[q], w.sux[q], w.Vp[q], w.svx[q], w.Pxx[q], w.Pxy[q], half);
  else
    return face_side(w.Hp[q], w.sHy[q], w.Vp[q], w.svy[q], w.Up[q], w.suy[q], w.Pyy[q], w.Pxy[q], half);
}

// The interior faces of one box row (x) or between two box rows (y) in one loop the compiler can
// vectorise. Cell pointers point at the right/upper cell of the first face; the left/lower cell is
// `s` before it. Outputs: mass, normal and tangential momentum flux.
RUNOUT_SIMD_CLONES void face_row(int n, std::ptrdiff_t s, const double* __restrict Hp, const double* __restrict sH,
                                 const double* __restrict Un, const double* __restrict sUn,
                                 const double* __restrict Ut, const double* __restrict sUt,
                                 const double* __restrict Pnn, const double* __restrict Pnt,
                                 const double* __restrict held, double* __restrict o0, double* __restrict on,
                                 double* __restrict ot) {
#pragma omp simd
  for (int k = 0; k < n; ++k) {
    const std::ptrdiff_t r = k, l = k - s;
    const FaceState L = face_side(Hp[l], sH[l], Un[l], sUn[l], Ut[l], sUt[l], Pnn[l], Pnt[l], 0.5);
    const FaceState R = face_side(Hp[r], sH[r], Un[r], sUn[r], Ut[r], sUt[r], Pnn[r], Pnt[r], -0.5);
    const Face f = face_flux(L, R, held[l] * held[r] != 0.0);
    o0[k] = f.f0;
    on[k] = f.f1;
    ot[k] = f.f2;
  }
}

}  // namespace

// A step face whose flux does not go through dam_face (a neighbour inactive or outside the domain):
// no wall reaction on either side (the update reads it at every step face).
template <bool X>
void Solver::no_reaction(TileWork& w, int ib, int jb) const {
  if constexpr (X) {
    const std::size_t k = w.fx(ib, jb);
    w.Wxa1[k] = w.Wxa2[k] = w.Wxb1[k] = w.Wxb2[k] = 0.0;
  } else {
    const std::size_t k = w.fy(ib, jb);
    w.Wya1[k] = w.Wya2[k] = w.Wyb1[k] = w.Wyb2[k] = 0.0;
  }
}

// The flux through a face between two cells of different dam heights (a dam's step): the flux of the
// sides reconstructed over the step (over_step), and on each side the wall's reaction to the part that
// does not pass (its wall flux minus that of the reconstructed side: no mass, pressure and the normal
// momentum turned back), stored for the update of that side's cell (TileWork Wx*, Wy*). A flow that
// cannot reach over the step meets a wall; the mass through the face is conserved exactly.
template <bool X>
Face Solver::dam_face(TileWork& w, int ia, int ja, int ib, int jb, bool held) const {
  const std::size_t a = idx(ia, ja), b = idx(ib, jb);
  const FaceState L = side_state<X>(w, w.at(ia, ja), 0.5), R = side_state<X>(w, w.at(ib, jb), -0.5);
  const double sa = X ? geo_.bx[a] : geo_.by[a], sb = X ? geo_.bx[b] : geo_.by[b];
  FaceState Ls = L, Rs = R;
  Ls.H = over_step(vmax(L.H, 0.0), vmax(L.un, 0.0), sa, g_, dam_[b] - dam_[a]);
  Rs.H = over_step(vmax(R.H, 0.0), vmax(-R.un, 0.0), sb, g_, dam_[a] - dam_[b]);
  const Face wl = wall_flux(L, true, held), wls = wall_flux(Ls, true, held), wr = wall_flux(R, false, held),
             wrs = wall_flux(Rs, false, held);
  if constexpr (X) {  // x faces: normal = x momentum
    const std::size_t k = w.fx(ib, jb);
    w.Wxa1[k] = wl.f1 - wls.f1;
    w.Wxa2[k] = wl.f2 - wls.f2;
    w.Wxb1[k] = wr.f1 - wrs.f1;
    w.Wxb2[k] = wr.f2 - wrs.f2;
  } else {  // y faces: normal = y momentum
    const std::size_t k = w.fy(ib, jb);
    w.Wya1[k] = wl.f2 - wls.f2;
    w.Wya2[k] = wl.f1 - wls.f1;
    w.Wyb1[k] = wr.f2 - wrs.f2;
    w.Wyb2[k] = wr.f1 - wrs.f1;
  }
  return face_flux(Ls, Rs, held);
}

template <bool X>
Face Solver::face(TileWork& w, int ia, int ja, int ib, int jb, bool lo, bool hi, Boundary2D blo,
                  Boundary2D bhi) const {
  // Flux through the face between cells a (left/below) and b; lo/hi: the face is a domain edge.
  const bool step = !lo && !hi && step_face(idx(ia, ja), idx(ib, jb));
  if (step) no_reaction<X>(w, ib, jb);  // dam_face writes it where the face takes the step's flux
  if (!lo && !hi && !w.all_active && cell_active(ia, ja) != cell_active(ib, jb)) return Face{0, 0, 0};
  const bool oa = !lo && w.has_outside && outside(ia, ja), ob = !hi && w.has_outside && outside(ib, jb);
  if (oa && ob) return Face{0, 0, 0};
  FaceState L{}, R{};
  if (!lo && !oa) L = side_state<X>(w, w.at(ia, ja), 0.5);
  if (!hi && !ob) R = side_state<X>(w, w.at(ib, jb), -0.5);
  if (lo) L = boundary_ghost(R, blo == Boundary2D::wall);
  if (hi) R = boundary_ghost(L, bhi == Boundary2D::wall);
  if (oa) L = outflow_ghost(R, false);
  if (ob) R = outflow_ghost(L, true);
  const bool held = !lo && !hi && !oa && !ob && w.held[w.at(ia, ja)] != 0.0 && w.held[w.at(ib, jb)] != 0.0;
  if (step && !oa && !ob) return dam_face<X>(w, ia, ja, ib, jb, held);
  return face_flux(L, R, held);
}

void Solver::faces(TileWork& w, int ci0, int ci1, int cj0, int cj1) const {
  // Every face of the cells (ci0..ci1-1, cj0..cj1-1) (the tile grown by one, clipped to the grid: what
  // the positivity limiter and the update read), from the box's predicted values. A face between an
  // active tile and an inactive one carries nothing: both its cells hold less than the activation
  // depth and the inactive side is not updated, so this keeps the volume exact.
  auto put_x = [&](int i, int j, const Face& f) {
    const std::size_t k = w.fx(i, j);
    w.Fx0[k] = f.f0;
    w.Fx1[k] = f.f1;
    w.Fx2[k] = f.f2;
  };
  auto put_y = [&](int i, int j, const Face& g) {  // g in (mass, normal, tangential)
    const std::size_t k = w.fy(i, j);
    w.Fy0[k] = g.f0;
    w.Fy1[k] = g.f2;
    w.Fy2[k] = g.f1;
  };
  // A face takes the row kernel where both its cells lie in the domain (inside its edges, neither
  // outside it), it is no dam's step and every tile around is active: there the general function
  // computes the same flux.
  auto plain = [&](int ia, int ja, int ib, int jb) {
    return w.all_active && !(w.has_outside && (outside(ia, ja) || outside(ib, jb))) &&
           !step_face(idx(ia, ja), idx(ib, jb));
  };
  for (int j = cj0; j < cj1; ++j)  // x faces: the face left of cell (i, j)
    for (int i = ci0; i <= ci1; ++i) {
      if (i > 0 && i < nx_ && plain(i - 1, j, i, j)) {
        int e = i + 1;  // a run of faces for the row kernel
        while (e <= ci1 && e < nx_ && plain(e - 1, j, e, j)) ++e;
        const std::size_t q = w.at(i, j), f = w.fx(i, j);
        face_row(e - i, 1, &w.Hp[q], &w.sHx[q], &w.Up[q], &w.sux[q], &w.Vp[q], &w.svx[q], &w.Pxx[q], &w.Pxy[q],
                 &w.held[q], &w.Fx0[f], &w.Fx1[f], &w.Fx2[f]);
        i = e - 1;
        continue;
      }
      put_x(i, j, face<true>(w, i - 1, j, i, j, i == 0, i == nx_, cfg_.west, cfg_.east));
    }
  for (int j = cj0; j <= cj1; ++j)  // y faces: the face below cell (i, j)
    for (int i = ci0; i < ci1; ++i) {
      if (j > 0 && j < ny_ && plain(i, j - 1, i, j)) {
        int e = i + 1;
        while (e < ci1 && plain(e, j - 1, e, j)) ++e;
        const std::size_t q = w.at(i, j), f = w.fy(i, j);
        face_row(e - i, w.bw, &w.Hp[q], &w.sHy[q], &w.Vp[q], &w.svy[q], &w.Up[q], &w.suy[q], &w.Pyy[q], &w.Pxy[q],
                 &w.held[q], &w.Fy0[f], &w.Fy2[f], &w.Fy1[f]);
        i = e - 1;
        continue;
      }
      put_y(i, j, face<false>(w, i, j - 1, i, j, j == 0, j == ny_, cfg_.south, cfg_.north));
    }
}

}  // namespace runout::engine::sh2d_detail
