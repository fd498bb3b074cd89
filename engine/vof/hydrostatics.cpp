#include "engine/vof/hydrostatics.hpp"

#include <algorithm>

namespace runout::engine::vof {

Hydrostatics::Hydrostatics(const Mesh& m, const VofConfig& cfg, const Fields& fields)
    : m_(m),
      fields_(fields),
      gravity_(cfg.gravity),
      rho2_(cfg.rho2),
      excess_(cfg.coulomb_pressure == CoulombPressure::excess),
      non_orth_(cfg.n_non_orthogonal_correctors > 0) {}

void Hydrostatics::resize() {
  gh_.assign(m_.cells(), 0);
  ghf_.assign(m_.faces(), 0);
  if (non_orth_) {
    non_orth_force_.assign(m_.faces(), 0);
    grad_rho_.assign(m_.cells(), Vec{});
    grad_p_.assign(m_.cells(), Vec{});
  }
}

void Hydrostatics::update_non_orthogonal_force() {
  if (!non_orth_) return;
  const int nc = m_.cells(), nf = m_.faces();
  for (int c = 0; c < nc; ++c) grad_rho_[c] = grad_p_[c] = Vec{};
  for (int f = 0; f < nf; ++f) {
    const int o = m_.owner[f];
    if (f < m_.n_internal) {
      const int nb = m_.neighbour[f];
      const double w = m_.weight[f];
      const double rf = w * fields_.rho[o] + (1 - w) * fields_.rho[nb], pf = w * fields_.p_rgh[o] + (1 - w) * fields_.p_rgh[nb];
      grad_rho_[o] = grad_rho_[o] + rf * m_.Sf[f];
      grad_rho_[nb] = grad_rho_[nb] - rf * m_.Sf[f];
      grad_p_[o] = grad_p_[o] + pf * m_.Sf[f];
      grad_p_[nb] = grad_p_[nb] - pf * m_.Sf[f];
    } else {
      grad_rho_[o] = grad_rho_[o] + fields_.rho[o] * m_.Sf[f];
      grad_p_[o] = grad_p_[o] + fields_.p_rgh[o] * m_.Sf[f];
    }
  }
  for (int c = 0; c < nc; ++c) {
    grad_rho_[c] = (1.0 / m_.volume[c]) * grad_rho_[c];
    grad_p_[c] = (1.0 / m_.volume[c]) * grad_p_[c];
  }
  for (int f = 0; f < m_.n_internal; ++f) {
    const int o = m_.owner[f], nb = m_.neighbour[f];
    const double w = m_.weight[f];
    const Vec& k = m_.non_orth[f];
    const double kr = w * dot(k, grad_rho_[o]) + (1 - w) * dot(k, grad_rho_[nb]);
    const double kp = w * dot(k, grad_p_[o]) + (1 - w) * dot(k, grad_p_[nb]);
    non_orth_force_[f] = -(ghf_[f] * kr + kp) / m_.magSf[f];
  }
}

void Hydrostatics::update(double t, const std::function<bool(int)>& opening, bool force) {
  if (force) gravity_set_ = false;
  const Vec g = gravity_(t);
  if (gravity_set_ && g.x == g_last_.x && g.y == g_last_.y && g.z == g_last_.z) return;
  gravity_set_ = true;
  g_last_ = g;
  const int nc = m_.cells(), nf = m_.faces();
  for (int c = 0; c < nc; ++c) gh_[c] = dot(g, m_.centre[c]);
  for (int f = 0; f < nf; ++f) ghf_[f] = dot(g, m_.Cf[f]);
  gh_ref_ = 1e300;
  for (int f = m_.n_internal; f < nf; ++f)
    if (opening(f)) gh_ref_ = std::min(gh_ref_, ghf_[f]);
  if (gh_ref_ == 1e300)  // a closed domain: the level is zero at its highest cell
    for (int c = 0; c < nc; ++c) gh_ref_ = std::min(gh_ref_, gh_[c]);
}

void Hydrostatics::zero() {
  std::fill(gh_.begin(), gh_.end(), 0.0);
  std::fill(ghf_.begin(), ghf_.end(), 0.0);
  gh_ref_ = 0;
  gravity_set_ = false;
}

}  // namespace runout::engine::vof
