// The momentum predictor: the momentum matrix solved with the last pressure's and the buoyancy's
// force, so that the viscous coupling (the Coulomb viscosity reaches 1e2 m2/s) is converged every
// step.
#include "engine/vof/momentum_eqn.hpp"

#include <algorithm>

namespace runout::engine::vof {

// The force per cell, V reconstruct(-ghf snGrad(rho) - snGrad(p_rgh)) |Sf|, over the active region
// (force_ holds the sum of the face forces times Sf); a face to the air at rest outside the region
// is an opening with the outside's pressure, as in the pressure equation. Walls and inflows: the
// pressure gradient normal to them is balanced (fixed flux).
void MomentumEqn::predictor_forces() {
  const Hydrostatics& hs = bc_ctx_.hydrostatics;
  auto& rec = force_;
  for (int c : region_.cells) rec[c] = Vec{};
  for (int f : region_.faces) {
    const int o = m_.owner[f];
    const bool ao = region_.active(o);
    double q = 0;  // force per area, normal to the face (along Sf)
    if (internal(m_, f)) {
      const int nb = m_.neighbour[f];
      const bool an = region_.active(nb);
      if (ao && an) {
        q = hs.face_force(f);
        rec[o] = rec[o] + q * m_.Sf[f];
        rec[nb] = rec[nb] + q * m_.Sf[f];
      } else {
        const int c = ao ? o : nb;
        const double sg = ao ? 1 : -1;  // Sf out of c
        q = hs.opening_force(f, c, hs.outside_p_rgh(f, c));  // out of c
        rec[c] = rec[c] + (sg * q) * m_.Sf[f];
      }
    } else if (ao && bcs_[f].opening_at(f)) {
      q = hs.opening_force(f, o, hs.outside_p_rgh(f, o));
      rec[o] = rec[o] + q * m_.Sf[f];
    }
  }
}

// The matrix over the predicted cells only, in ascending order: the active region's cells, and
// under the consistent coupling only the material's (alpha >= consistent_alpha); the air around
// them keeps its velocity (the cells' coefficients to it go to the right-hand side), as under PISO.
// Predicting the air too let the cell-reconstructed buoyancy force drive air currents over a
// resting heap's stair-stepped surface (0.1 m/s) that dragged it along at 2 mm/s
// (docs/design/vof.md). The system's size follows the material, not the mesh.
//
// Split over ranks, each rank's rows are its own predicted cells, the ranks one after another; a
// ghost's row (a column of the rank's rows) is its owner's.
void MomentumEqn::predictor_rows(const Fields& F) {
  const bool material_only = cfg_.consistent;
  const Ranks& ranks = region_.ranks();
  rows_.clear();
  for (int c : region_.cells)
    if (!material_only || F.alpha[c] >= cfg_.consistent_alpha) rows_.push_back(c);
  std::sort(rows_.begin(), rows_.end());
  if (row_of_.size() != std::size_t(m_.cells())) row_of_.assign(m_.cells(), -1);
  for (int r = 0; r < int(rows_.size()); ++r) row_of_[rows_[r]] = r;
  n_own_rows_ = 0;
  for (int c : rows_) n_own_rows_ += ranks.own(c) ? 1 : 0;
  const int n = n_own_rows_;
  if (ranks.distributed()) {
    int first_row = 0;
    MPI_Exscan(&n, &first_row, 1, MPI_INT, MPI_SUM, ranks.comm().comm);
    if (ranks.comm().rank == 0) first_row = 0;
    total_rows_ = ranks.comm().sum((long long)n);
    global_of_.assign(m_.cells(), -1);
    for (int r = 0; r < n; ++r) global_of_[rows_[r]] = first_row + r;
    ranks.sync(global_of_);
  } else {
    total_rows_ = n;
  }
  const auto col = [&](int c) { return ranks.distributed() ? global_of_[c] : row_of_[c]; };
  const auto mine = [&](int r) { return r >= 0 && r < n; };
  const auto& cO = UEqn_.upper;
  const auto& cN = UEqn_.lower;
  known_.assign(n, Vec{});
  // Per own row: the diagonal and an entry per predicted neighbour; columns sorted afterwards.
  A_.start.assign(std::size_t(n) + 1, 1);
  A_.start[0] = 0;
  for (int f : region_.faces) {
    if (f >= m_.n_internal) break;
    const int ro = row_of_[m_.owner[f]], rn = row_of_[m_.neighbour[f]];
    if (ro >= 0 && rn >= 0) {
      if (mine(ro)) ++A_.start[ro + 1];
      if (mine(rn)) ++A_.start[rn + 1];
    }
  }
  for (int r = 0; r < n; ++r) A_.start[r + 1] += A_.start[r];
  A_.col.resize(A_.start[n]);
  A_.val.resize(A_.start[n]);
  std::vector<PetscInt> next(A_.start.begin(), A_.start.end() - 1);
  for (int r = 0; r < n; ++r) A_.col[next[r]] = col(rows_[r]), A_.val[next[r]++] = UEqn_.diag[rows_[r]];
  for (int f : region_.faces) {
    if (f >= m_.n_internal) break;
    const int o = m_.owner[f], nb = m_.neighbour[f];
    const int ro = row_of_[o], rn = row_of_[nb];
    if (ro >= 0 && rn >= 0) {
      if (mine(ro)) A_.col[next[ro]] = col(nb), A_.val[next[ro]++] = -cO[f];
      if (mine(rn)) A_.col[next[rn]] = col(o), A_.val[next[rn]++] = -cN[f];
    } else if (mine(ro) && region_.active(nb)) {
      known_[ro] = known_[ro] + cO[f] * F.U[nb];
    } else if (mine(rn) && region_.active(o)) {
      known_[rn] = known_[rn] + cN[f] * F.U[o];
    }
  }
  for (int r = 0; r < n; ++r) {  // a handful of entries per row: insertion sort
    for (PetscInt i = A_.start[r] + 1; i < A_.start[r + 1]; ++i)
      for (PetscInt j = i; j > A_.start[r] && A_.col[j - 1] > A_.col[j]; --j) {
        std::swap(A_.col[j - 1], A_.col[j]);
        std::swap(A_.val[j - 1], A_.val[j]);
      }
  }
}

int MomentumEqn::predict(Fields& F, double t) {
  predictor_forces();
  predictor_rows(F);
  solver_.set_matrix(A_, total_rows_);
  const int n = n_own_rows_;
  int its_total = 0;
  auto b = std::vector<double>(n), x = b;
  for (int i = 0; i < dims_; ++i) {
    for (int r = 0; r < n; ++r) {
      const int c = rows_[r];
      const Vec Fc = reconstruct_(c, force_[c]);
      b[r] = comp(UEqn_.source[c], i) + m_.volume[c] * comp(Fc, i) + comp(known_[r], i);
      x[r] = comp(F.U[c], i);
    }
    its_total += solver_.solve(b, x, t);
    for (int r = 0; r < n; ++r) comp_ref(F.U[rows_[r]], i) = x[r];
  }
  for (int c : rows_) row_of_[c] = -1;
  region_.ranks().sync(F.U);
  return its_total;
}

}  // namespace runout::engine::vof
