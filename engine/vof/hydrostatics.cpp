#include "engine/vof/hydrostatics.hpp"

#include "engine/vof/fv/grad.hpp"
#include "engine/vof/fv/ops.hpp"
#include "engine/vof/fv/parallel.hpp"

#include <algorithm>

namespace runout::engine::vof {

Hydrostatics::Hydrostatics(const Mesh& m, const VofConfig& cfg, const Fields& fields, const Ranks& ranks)
    : m_(m),
      fields_(fields),
      ranks_(ranks),
      gravity_(cfg.gravity),
      rho2_(cfg.rho2),
      excess_(cfg.coulomb_pressure == CoulombPressure::excess),
      non_orth_(cfg.n_non_orthogonal_correctors > 0),
      limiter_(cfg.non_orthogonal_limiter) {}

void Hydrostatics::resize() {
  gh_.assign(m_.cells(), 0);
  ghf_.assign(m_.faces(), 0);
  if (non_orth_) non_orth_force_.assign(m_.faces(), 0);
}

void Hydrostatics::update_non_orthogonal_force(const CellFaces& cell_faces, const std::vector<int>& faces, const std::vector<int>& cells) {
  if (!non_orth_) return;
  gauss_gradient_hydrostatic(m_, cell_faces, cells, fields_.p, fields_.rho, gh_, ghf_, grad_p_);
  ranks_.sync(grad_p_);
  parallel_each(faces, [&](int f) {
    if (f >= m_.n_internal) return;
    const Vec& k = m_.non_orth[f];
    const double rho_f = interpolate(m_, f, fields_.rho);
    const double corr = -(dot(k, interpolate(m_, f, grad_p_)) - rho_f * dot(k, g_last_)) / m_.magSf[f];
    non_orth_force_[f] = limited_correction(corr, orthogonal_force(f), limiter_);
  });
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
  gh_ref_ = ranks_.comm().min(gh_ref_);  // the whole mesh's openings
  if (gh_ref_ == 1e300) {  // a closed domain: the level is zero at its highest cell
    for (int c = 0; c < nc; ++c) gh_ref_ = std::min(gh_ref_, gh_[c]);
    gh_ref_ = ranks_.comm().min(gh_ref_);
  }
}

void Hydrostatics::zero() {
  std::fill(gh_.begin(), gh_.end(), 0.0);
  std::fill(ghf_.begin(), ghf_.end(), 0.0);
  gh_ref_ = 0;
  gravity_set_ = false;
}

}  // namespace runout::engine::vof
