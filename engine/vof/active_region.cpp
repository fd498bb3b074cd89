#include "engine/vof/active_region.hpp"

#include <algorithm>

namespace runout::engine::vof {

bool ActiveRegion::update(bool force) {
  const int nc = m_.cells();
  if (cfg_.active_layers <= 0) {
    if (n_active == nc && !force) return false;
    set(std::vector<int>(nc, 0));
    return true;
  }
  // Each rank checks its part (no message inside the checks); the region stays only where every
  // rank finds it still holds the material and the seeds.
  bool keep = !force && n_active_total > 0;
  if (keep) keep = material_inside();
  if (keep) keep = seeds_inside_here();
  if (ranks_.comm().any(!keep)) {
    set(layers_from_material());
    return true;
  }
  return false;
}

// Every cell next to a boundary face that seeds the region now (an inflow, a coupled inflow while
// material enters) lies inside it.
bool ActiveRegion::seeds_inside() const { return !ranks_.comm().any(!seeds_inside_here()); }

bool ActiveRegion::seeds_inside_here() const {
  for (int f = m_.n_internal; f < m_.faces(); ++f)
    if (bcs_[f].seeds_active_region() && bcs_[f].seeds_active_region_at(f) && !active(m_.owner[f])) return false;
  return true;
}

// Cheap check: material, and two layers around it, must lie inside the region. Material can
// appear only where faces of the region carry flux, so the cells next to it (the halo) are the
// only candidates; marks carry a stamp instead of being cleared.
bool ActiveRegion::material_inside() {
  if (++stamp_ == 0) {
    std::fill(mark_.begin(), mark_.end(), 0u);
    stamp_ = 1;
  }
  std::vector<int>& front = bfs_a_;
  std::vector<int>& next = bfs_b_;
  front.clear();
  for (int c : halo)
    if (fields_.alpha[c] > cfg_.active_alpha) {
      mark_[c] = stamp_;
      front.push_back(c);
    }
  bool inside = true;
  for (int k = 0; k <= std::min(2, cfg_.active_layers) && inside; ++k) {
    next.clear();
    for (int c : front) {
      if (index[c] < 0) {
        inside = false;
        break;
      }
      for (int f : cell_faces_[c]) {
        if (f >= m_.n_internal) continue;
        const int other = across(m_, f, c);
        if (mark_[other] != stamp_) {
          mark_[other] = stamp_;
          next.push_back(other);
        }
      }
    }
    front.swap(next);
  }
  return inside;
}

// Distance in layers from the material (breadth-first over faces), up to `active_layers`; air
// beyond the layers joins the reservoir (-1) only where it connects to an atmosphere opening
// through other such cells: an enclosed pocket (under a lid, in a closed box) keeps its volume, so
// it stays in the computation (layers + 1). Split over ranks, each layer's distances go to the
// ghosts before the next layer grows from them, so that every own cell's distance is the whole
// mesh's.
std::vector<int> ActiveRegion::layers_from_material() const {
  const int nc = m_.cells(), nf = m_.faces(), layers = cfg_.active_layers;
  std::vector<int> d(nc, -1), front, next;
  for (int c = 0; c < nc; ++c)
    if (fields_.alpha[c] > cfg_.active_alpha) {
      d[c] = 0;
      front.push_back(c);
    }
  for (int f = m_.n_internal; f < nf; ++f)
    if (bcs_[f].seeds_active_region_at(f)) {
      const int o = m_.owner[f];
      if (d[o] < 0) {
        d[o] = 0;
        front.push_back(o);
      }
    }
  ranks_.sync(d);
  for (int k = 1; k <= layers && ranks_.comm().any(!front.empty()); ++k) {
    next.clear();
    for (int c : front)
      for (int f : cell_faces_[c]) {
        if (f >= m_.n_internal) continue;
        const int other = across(m_, f, c);
        if (d[other] < 0) {
          d[other] = k;
          next.push_back(other);
        }
      }
    if (ranks_.distributed()) {  // the layer as the ghosts' owners grew it
      ranks_.sync(d);
      next.clear();
      for (int c = 0; c < nc; ++c)
        if (d[c] == k) next.push_back(c);
    }
    front.swap(next);
  }
  flood_from_openings(d);
  return d;
}

// The air beyond the layers that an opening reaches through other such air joins the reservoir
// (stays -1); the rest takes layers + 1. Split over ranks, each rank floods its part from the
// openings and from the cells its neighbours have reached, until no rank reaches further.
void ActiveRegion::flood_from_openings(std::vector<int>& d) const {
  const int nc = m_.cells(), nf = m_.faces();
  std::vector<int> stack;
  std::vector<int> out(nc, 0);
  for (int f = m_.n_internal; f < nf; ++f)
    if (bcs_[f].opening_at(f)) {
      const int o = m_.owner[f];
      if (d[o] < 0 && !out[o]) {
        out[o] = 1;
        stack.push_back(o);
      }
    }
  for (;;) {
    while (!stack.empty()) {
      const int c = stack.back();
      stack.pop_back();
      for (int f : cell_faces_[c]) {
        if (f >= m_.n_internal) continue;
        const int other = across(m_, f, c);
        if (d[other] < 0 && !out[other]) {
          out[other] = 1;
          stack.push_back(other);
        }
      }
    }
    if (!ranks_.distributed()) break;
    const auto before = out;
    ranks_.sync(out);
    if (!ranks_.comm().any(out != before)) break;
    for (int c = 0; c < nc; ++c)
      if (out[c]) stack.push_back(c);
  }
  for (int c = 0; c < nc; ++c)
    if (d[c] < 0 && !out[c]) d[c] = cfg_.active_layers + 1;
}

void ActiveRegion::set(const std::vector<int>& d) {
  const int nc = m_.cells(), nf = m_.faces();
  Fields& F = fields_;
  index.assign(nc, -1);
  cells.clear();
  for (int c = 0; c < nc; ++c)
    if (d[c] >= 0) {
      index[c] = int(cells.size());
      cells.push_back(c);
    }
  n_active = int(cells.size());
  std::vector<char> in_halo(nc, 0);
  faces.clear();
  face_in.assign(std::size_t(nf), 0);
  for (int f = 0; f < nf; ++f) {
    const int o = m_.owner[f];
    const bool ao = index[o] >= 0;
    const bool an = f < m_.n_internal && index[m_.neighbour[f]] >= 0;
    if (ao || an) {
      faces.push_back(f);
      face_in[f] = 1;
      in_halo[o] = 1;
      if (f < m_.n_internal) in_halo[m_.neighbour[f]] = 1;
    } else {
      F.phi[f] = 0;
      F.alpha_phi[f] = F.rho_phi[f] = 0;
    }
  }
  // Cells joining the halo start from their resting state (their old-time values are stale).
  if (halo_flag_.size() != std::size_t(nc)) halo_flag_.assign(nc, 0);
  for (int c = 0; c < nc; ++c)
    if (in_halo[c] && !halo_flag_[c]) {
      if (index[c] < 0) F.U[c] = Vec{};
      F.rho_old[c] = F.rho[c];
      F.U_old[c] = F.U[c];
      F.mu[c] = mixture_.mu(F.alpha[c], F.nu1[c]);
    }
  halo_flag_ = in_halo;
  halo.clear();
  frozen_volume = 0;
  frozen_min = 1e300;
  frozen_max = -1e300;
  for (int c = 0; c < nc; ++c) {
    if (in_halo[c]) {
      halo.push_back(c);
    } else if (ranks_.own(c)) {
      const double a = F.alpha[c];
      frozen_volume += a * m_.volume[c];
      frozen_min = std::min(frozen_min, a);
      frozen_max = std::max(frozen_max, a);
    }
    if (index[c] < 0) {  // air at rest outside the region
      F.U[c] = Vec{};
      F.p[c] = hydrostatics_.still_air_p(hydrostatics_.gh(c));
      F.p_rgh[c] = F.p[c] - F.rho[c] * hydrostatics_.gh(c);
    }
  }
  if (mark_.size() != std::size_t(nc)) mark_.assign(nc, 0u);
  const Comm& comm = ranks_.comm();
  frozen_volume = comm.sum(frozen_volume);
  frozen_min = comm.min(frozen_min);
  frozen_max = comm.max(frozen_max);
  if (cells_total_ < 0) cells_total_ = comm.sum((long long)ranks_.owned(nc));
  number_rows();
  // A ghost's resting values as its owner set them (a ghost may join the owner's halo, not this part's).
  ranks_.sync(F.U);
  ranks_.sync(F.mu);
  ranks_.sync(F.p);
  ranks_.sync(F.p_rgh);
}

// The pressure system's rows: each rank's own region cells in order, the ranks one after another;
// a ghost's row is its owner's.
void ActiveRegion::number_rows() {
  const int nc = m_.cells();
  n_own_active = 0;
  for (int c : cells)
    if (ranks_.own(c)) ++n_own_active;
  const Comm& comm = ranks_.comm();
  row_offset = 0;
  if (comm.size > 1) MPI_Exscan(&n_own_active, &row_offset, 1, MPI_INT, MPI_SUM, comm.comm);
  if (comm.rank == 0) row_offset = 0;
  n_active_total = comm.sum((long long)n_own_active);
  global_row.assign(nc, -1);
  for (int c = 0; c < nc; ++c)
    if (index[c] >= 0 && ranks_.own(c)) global_row[c] = row_offset + index[c];
  ranks_.sync(global_row);
}

ActiveRegion::Nonzeros ActiveRegion::pressure_nonzeros() const {
  Nonzeros nz;
  nz.own.assign(std::size_t(std::max(1, n_own_active)), 1);
  nz.off.assign(nz.own.size(), 0);
  auto count = [&](int row_cell, int other) {
    if (!ranks_.own(row_cell)) return;
    ++(ranks_.own(other) ? nz.own : nz.off)[std::size_t(index[row_cell])];
  };
  for (int f = 0; f < m_.n_internal; ++f) {
    const int o = m_.owner[f], n = m_.neighbour[f];
    if (index[o] >= 0 && index[n] >= 0) {
      count(o, n);
      count(n, o);
    }
  }
  return nz;
}

}  // namespace runout::engine::vof
