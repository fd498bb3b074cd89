// One tile's step of the depth-averaged 2D scheme: which cells it computes (the box within reach of
// material) and the order of the stages on them: the predictor on the box (predictor.cpp), the face
// fluxes (fluxes.cpp), the positivity limiter and the update (update.cpp).
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "engine/sh2d/solver.hpp"

namespace runout::engine::sh2d_detail {

// The cells of the tile that can change in this step: those within two cells (the scheme's stencil)
// of a cell holding material, as a box. Every other cell of the tile is empty and stays empty, bit
// for bit: its fluxes, sources and friction are all zero. Empty when the tile and its two-cell
// halo hold nothing.
CellBox Solver::material_box(int i0, int i1, int j0, int j1) const {
  if (!cfg_.skip_inactive || !cfg_.skip_empty) return CellBox{i0, i1, j0, j1};
  const auto& Hs = H_[cur_];
  const int xa = std::max(i0 - 2, 0), xb = std::min(i1 + 2, nx_), ya = std::max(j0 - 2, 0), yb = std::min(j1 + 2, ny_);
  int a0 = xb, a1 = xa - 1, b0 = yb, b1 = ya - 1;
  for (int j = ya; j < yb; ++j) {
    const double* row = &Hs[idx(0, j)];
    int first = xa;
    while (first < xb && !(row[first] > 0)) ++first;
    if (first == xb) continue;
    int last = xb - 1;
    while (!(row[last] > 0)) --last;
    a0 = std::min(a0, first);
    a1 = std::max(a1, last);
    b0 = std::min(b0, j);
    b1 = j;
  }
  if (a1 < a0) return CellBox{i0, i0, j0, j0};
  return CellBox{std::max(a0 - 2, i0), std::min(a1 + 3, i1), std::max(b0 - 2, j0), std::min(b1 + 3, j1)};
}

// Empties the tile's cells outside box c in the new time level, which still holds the state of the
// step before: the cells that may hold something there (filled_) and lie outside c. Afterwards the
// level's filled box is c.
void Solver::clear_outside(int tt, const CellBox& c) {
  const int nb = 1 - cur_;
  const CellBox o = filled_[nb][tt];
  auto clear = [&](int j, int a, int b) {
    if (b <= a) return;
    const std::size_t k = idx(a, j), n = std::size_t(b - a);
    for (auto* v : {&H_[nb], &HU_[nb], &HV_[nb], &U_[nb], &V_[nb]}) std::fill_n(v->begin() + std::ptrdiff_t(k), n, 0.0);
  };
  for (int j = o.j0; j < o.j1; ++j) {
    if (c.empty() || j < c.j0 || j >= c.j1) {
      clear(j, o.i0, o.i1);
      continue;
    }
    clear(j, o.i0, std::min(o.i1, c.i0));
    clear(j, std::max(o.i0, c.i1), o.i1);
  }
  filled_[nb][tt] = c;
}

// The whole tile may hold something in both time levels (set-up, a frozen tile, a secondary release).
void Solver::fill_whole(int tt) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  filled_[0][tt] = filled_[1][tt] = CellBox{i0, i1, j0, j1};
}

long Solver::step_tile(int tt, double t, double dt, TileWork& w) {
  int i0, i1, j0, j1;
  tile_range(tt, i0, i1, j0, j1);
  const CellBox c = material_box(i0, i1, j0, j1);
  clear_outside(tt, c);
  if (c.empty()) {  // nothing within reach: the tile's sums are those of an empty tile
    tile_mass_[tt] = tile_ke_[tt] = tile_speed_[tt] = tile_rate_[tt] = 0.0;
    tile_wet_[tt] = 0;
    return 0;
  }
  w.bi0 = std::max(c.i0 - 2, 0);
  w.bj0 = std::max(c.j0 - 2, 0);
  w.bw = std::min(c.i1 + 2, nx_) - w.bi0;
  w.bh = std::min(c.j1 + 2, ny_) - w.bj0;
  const int ti = tt % ntx_, tj = tt / ntx_;
  w.has_outside = box_out_[tt] != 0;
  w.all_active = true;
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) {
      const int u = ti + di, v = tj + dj;
      if (u >= 0 && v >= 0 && u < ntx_ && v < nty_ && !active_flag_[v * ntx_ + u]) w.all_active = false;
    }
  switch (cfg_.limiter) {
    case Limiter::minmod: predictor<Limiter::minmod>(w, dt); break;
    case Limiter::vanleer: predictor<Limiter::vanleer>(w, dt); break;
    case Limiter::superbee: predictor<Limiter::superbee>(w, dt); break;
  }
  faces(w, std::max(c.i0 - 1, 0), std::min(c.i1 + 1, nx_), std::max(c.j0 - 1, 0), std::min(c.j1 + 1, ny_));
  tile_limited_[tt] += positivity(w, c.i0, c.i1, c.j0, c.j1, dt);
  update(tt, w, c, t, dt);
  return long(c.i1 - c.i0) * (c.j1 - c.j0);
}

}  // namespace runout::engine::sh2d_detail
