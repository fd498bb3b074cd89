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
  if (!force && n_active > 0 && material_inside() && seeds_inside()) return false;
  set(layers_from_material());
  return true;
}

// Every cell next to a boundary face that seeds the region now (an inflow, a coupled inflow while
// material enters) lies inside it.
bool ActiveRegion::seeds_inside() const {
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
// it stays in the computation (layers + 1).
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
  for (int k = 1; k <= layers && !front.empty(); ++k) {
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
    front.swap(next);
  }
  std::vector<int> stack;
  std::vector<char> out(nc, 0);
  for (int f = m_.n_internal; f < nf; ++f)
    if (bcs_[f].opening_at(f)) {
      const int o = m_.owner[f];
      if (d[o] < 0 && !out[o]) {
        out[o] = 1;
        stack.push_back(o);
      }
    }
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
  for (int c = 0; c < nc; ++c)
    if (d[c] < 0 && !out[c]) d[c] = layers + 1;
  return d;
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
    } else {
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
}

std::vector<int> ActiveRegion::pressure_nonzeros() const {
  std::vector<int> nnz(std::size_t(std::max(1, n_active)), 1);
  for (int f = 0; f < m_.n_internal; ++f) {
    const int io = index[m_.owner[f]], in = index[m_.neighbour[f]];
    if (io >= 0 && in >= 0) {
      ++nnz[io];
      ++nnz[in];
    }
  }
  return nnz;
}

}  // namespace runout::engine::vof
