#include "engine/vof/momentum_eqn.hpp"

#include "engine/vof/fv/grad.hpp"
#include "engine/vof/fv/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace runout::engine::vof {

MomentumEqn::MomentumEqn(const Mesh& m, const VofConfig& cfg, const BcContext& bc_ctx, const Boundaries& bcs, const ActiveRegion& region,
                         const Reconstruction& reconstruct, int dims)
    : m_(m), cfg_(cfg), bc_ctx_(bc_ctx), bcs_(bcs), region_(region), reconstruct_(reconstruct), dims_(dims) {
  const auto nc = std::size_t(m.cells()), nf = std::size_t(m.faces());
  UEqn_.resize(m.cells(), m.faces());
  rAU.assign(nc, 0);
  rAtU = rAU;
  H1_ = rAU;
  rAUf.assign(nf, 0);
  rAtUf = rAUf;
  HbyA.assign(nc, Vec{});
  H_ = HbyA;
  force_ = HbyA;
  diag_o_.assign(nf, 0);
  diag_n_ = diag_o_;
  face_vec_.assign(nf, Vec{});
  drA.assign(nc, 0);
  drAt = drA;
  // (Split over ranks by whole columns, a rank may hold none: the columns count on every rank alike.)
  column_ = region.ranks().comm().any(cfg.column_friction.columns.columns() > 0);
  if (column_) {
    drag_.drag.assign(nc, 0);
    drag_.normal.assign(nc, Vec{});
    drag_.given_back.assign(nc, Vec{});
    diag_no_drag_.assign(nc, 0);
  }
}

namespace {
double sq_along(const Vec& n, const Vec& s) {
  const double c = dot(n, s) / norm(s);
  return c * c;
}
}  // namespace

double MomentumEqn::rA_along(bool consistent, int c, const Vec& s) const {
  const double r = consistent ? rAtU[c] : rAU[c], dr = consistent ? drAt[c] : drA[c];
  return dr != 0 ? r + dr * sq_along(drag_.normal[c], s) : r;
}

Vec MomentumEqn::rA_apply(bool consistent, int c, const Vec& v) const {
  const double r = consistent ? rAtU[c] : rAU[c], dr = consistent ? drAt[c] : drA[c];
  if (dr == 0) return r * v;
  const Vec& n = drag_.normal[c];
  return r * v + (dr * dot(n, v)) * n;
}

Vec MomentumEqn::rA_difference_apply(int c, const Vec& v) const {
  const double dr = drA[c] - drAt[c];
  if (drA[c] == 0 && drAt[c] == 0) return (rAU[c] - rAtU[c]) * v;
  const Vec& n = drag_.normal[c];
  return (rAU[c] - rAtU[c]) * v + (dr * dot(n, v)) * n;
}

void MomentumEqn::setup_predictor() { solver_.setup(cfg_.momentum_rtol, region_.ranks()); }

void MomentumEqn::velocity_gradient(Fields& F) const {
  // Per cell of the halo over its faces of the region (the outer cells' other faces carry nothing).
  const auto face_U = [&](int f, int) { return internal(m_, f) ? interpolate(m_, f, F.U) : bcs_[f].velocity(bc_ctx_, f); };
  grad(m_, region_.cell_faces(), region_.halo, face_U, F.gradU, region_.face_in_region());
  region_.ranks().sync(F.gradU);
}

void MomentumEqn::update_viscosity(Fields& F) const {
  velocity_gradient(F);
  parallel_each(region_.cells, [&](int c) {
    F.nu1[c] = bc_ctx_.viscosity.nu(bc_ctx_.hydrostatics.confining_pressure(c), strain_rate(F.gradU[c]));
    F.mu[c] = bc_ctx_.mixture.mu(F.alpha[c], F.nu1[c]);
  });
  region_.ranks().sync(F.nu1);
  region_.ranks().sync(F.mu);
}

// Boundary values and the transpose viscous part are taken from the current velocity.
void MomentumEqn::build(const Fields& F, double dt) {
  transient(F, dt);
  if (cfg_.viscous_transpose != Transpose::off) transpose_stress(F);
  convection_diffusion(F);
  if (cfg_.momentum_convection == Convection::limited_linear) limited_linear_correction(F);
  boundary_terms(F);
  if (cfg_.side_walls.width > 0) side_wall_friction(F);
  if (column_) {
    // The diagonal without the drag (A - D loses its digits where the drag outweighs it).
    parallel_each(region_.halo, [&](int c) { diag_no_drag_[c] = UEqn_.diag[c]; });
    bed_load = add_column_friction(m_, cfg_.column_friction, cfg_.rho1, F, bc_ctx_.hydrostatics, region_, UEqn_, drag_);
    const Ranks& ranks = region_.ranks();
    if (ranks.distributed()) {  // the whole mesh's load; a ghost's drag normal as its owner's (rA_along)
      const Comm& comm = ranks.comm();
      bed_load.weight_normal = comm.sum(bed_load.weight_normal);
      bed_load.centripetal = comm.sum(bed_load.centripetal);
      bed_load.face_pressure = comm.sum(bed_load.face_pressure);
      bed_load.friction_load = comm.sum(bed_load.friction_load);
      bed_load.columns = int(comm.sum((long long)bed_load.columns));
      ranks.sync(drag_.normal);
    }
  }
  coefficients(F, dt);
}

// The friction of the side walls a plane set-up stands for (VofConfig::side_walls): two walls W
// apart, each carrying tan(delta_w) p against the velocity, 2 tan(delta_w) p / W per unit volume of
// material (p the confining pressure, as the granular viscosity takes it), on the material's share
// alpha of the cell. Implicit as the Coulomb friction bed: a drag of the force over
// max(|u|, creep speed) on the diagonal, so that the force's magnitude is the friction while the
// material moves and material held by less comes to rest.
void MomentumEqn::side_wall_friction(const Fields& F) {
  const auto& sw = cfg_.side_walls;
  const double k = 2 * sw.tan_delta / sw.width;
  parallel_each(region_.halo, [&](int c) {
    const double p = std::max(bc_ctx_.hydrostatics.confining_pressure(c), 0.0);
    UEqn_.diag[c] += F.alpha[c] * k * p * m_.volume[c] / std::max(norm(F.U[c]), sw.creep_speed);
  });
}

// ddt(rho, U), Euler implicit.
void MomentumEqn::transient(const Fields& F, double dt) {
  parallel_each(region_.halo, [&](int c) {
    const double V = m_.volume[c];
    UEqn_.diag[c] = F.rho[c] * V / dt;
    UEqn_.source[c] = (F.rho_old[c] * V / dt) * F.U_old[c];
  });
}

// Transpose part of the viscous stress, explicit and in divergence form as interFoam has it: sum
// over faces of mu_f (grad U)^T_f . Sf. (The equivalent cell form (grad U) . grad mu, with mu
// jumping nine orders of magnitude across the interface, moved a heap that should rest.) The face
// viscosity is interpolated linearly or taken as the harmonic mean (VofConfig::viscous_transpose;
// validation.md B1 and B2 for what each does).
void MomentumEqn::transpose_stress(const Fields& F) {
  const bool harmonic = cfg_.viscous_transpose == Transpose::harmonic;
  const auto& G = F.gradU;
  auto& b = UEqn_.source;
  parallel_each(region_.faces, [&](int f) {
    const int o = m_.owner[f];
    const bool in = internal(m_, f);
    const int nb = in ? m_.neighbour[f] : o;
    const double w = in ? m_.weight[f] : 1.0;
    const double mo = F.mu[o], mn = F.mu[nb];
    const double muf = harmonic ? mo * mn / (w * mn + (1 - w) * mo) : (in ? interpolate(m_, f, F.mu) : mo);
    const Vec& S = m_.Sf[f];
    Vec t;
    for (int i = 0; i < 3; ++i) {
      double v = 0;
      for (int j = 0; j < 3; ++j) v += (w * G[o].g[i][j] + (1 - w) * G[nb].g[i][j]) * comp(S, j);
      add_comp(t, i, muf * v);
    }
    face_vec_[f] = t;
  });
  // Into the owner (+) and the neighbour (-), per cell over its faces in ascending order.
  const CellFaces& cf = region_.cell_faces();
  parallel_each(region_.halo, [&](int c) {
    Vec sum = b[c];
    for (int f : cf[c]) {
      if (!region_.face_in[f]) continue;
      sum = m_.owner[f] == c ? sum + face_vec_[f] : sum - face_vec_[f];
    }
    b[c] = sum;
  });
}

// div(rho_phi, U) upwind and laplacian(mu_f, U) with the linear face viscosity (interFoam's
// twoPhaseMixture::muf(), which weights each phase's interpolated viscosity by the face's phase
// fraction, gave the same B2 figures to the third digit under PISO), over the internal faces.
// Row o: + max(F,0) U_o + min(F,0) U_nb + D (U_o - U_nb); row nb: the flux out of nb is -F.
void MomentumEqn::convection_diffusion(const Fields& F) {
  const auto& faces = region_.faces;
  const int n_in = int(std::lower_bound(faces.begin(), faces.end(), m_.n_internal) - faces.begin());
  parallel_for(n_in, [&](int k) {
    const int f = faces[std::size_t(k)];
    const double Fm = F.rho_phi[f];
    const double D = interpolate(m_, f, F.mu) * m_.magSf[f] * m_.delta_coeff[f];
    diag_o_[f] = std::max(Fm, 0.0) + D;
    UEqn_.upper[f] = D - std::min(Fm, 0.0);
    diag_n_[f] = std::max(-Fm, 0.0) + D;
    UEqn_.lower[f] = D - std::min(-Fm, 0.0);
  });
  const CellFaces& cf = region_.cell_faces();
  parallel_each(region_.halo, [&](int c) {
    double d = UEqn_.diag[c];
    for (int f : cf[c]) {
      if (f >= m_.n_internal || !region_.face_in[f]) continue;
      d += m_.owner[f] == c ? diag_o_[f] : diag_n_[f];
    }
    UEqn_.diag[c] = d;
  });
}

// limitedLinearV 1 (interFoam's damBreak): the face value moves from upwind towards the linear one
// by a TVD limiter of one ratio per face (the vector's own direction), as a deferred correction on
// the right-hand side, so the matrix stays upwind.
void MomentumEqn::limited_linear_correction(const Fields& F) {
  auto& b = UEqn_.source;
  for (int f : region_.faces) {
    if (!internal(m_, f)) break;
    const double Fm = F.rho_phi[f];
    if (Fm == 0) continue;
    const int o = m_.owner[f], nb = m_.neighbour[f];
    const Vec Uo = F.U[o], Un = F.U[nb];
    const Vec dU = Un - Uo;
    const double gf = dot(dU, dU);
    if (!(gf > 0)) continue;
    const Vec d = m_.centre[nb] - m_.centre[o];
    const auto& g = F.gradU[Fm > 0 ? o : nb].g;
    Vec dg;
    for (int j = 0; j < 3; ++j) {
      double v = 0;
      for (int i = 0; i < 3; ++i) v += comp(d, i) * g[i][j];
      add_comp(dg, j, v);
    }
    const double gc = dot(dU, dg);
    const double r = std::abs(gc) >= 1000 * gf ? 2 * 1000 * (gc > 0 ? 1 : -1) - 1 : 2 * gc / gf - 1;
    const double lim = std::clamp(2 * r, 0.0, 1.0);
    const Vec Ulin = interpolate(m_, f, F.U);
    const Vec corr = (Fm * lim) * (Ulin - (Fm > 0 ? Uo : Un));
    b[o] = b[o] - corr;
    b[nb] = b[nb] + corr;
  }
}

// Each boundary face's condition (its shear or friction), then the convection through it: what
// leaves takes the cell's velocity, what enters brings the boundary's.
void MomentumEqn::boundary_terms(const Fields& F) {
  for (int f : region_.faces) {
    if (internal(m_, f)) continue;
    const int o = m_.owner[f];
    const double Fm = F.rho_phi[f];
    const Vec Ub = bcs_[f].velocity(bc_ctx_, f);
    bcs_[f].momentum(bc_ctx_, f, Ub, UEqn_.diag[o], UEqn_.source[o]);
    if (Fm >= 0) {
      UEqn_.diag[o] += Fm;
    } else {
      UEqn_.source[o] = UEqn_.source[o] + (-Fm) * Ub;
    }
  }
}

// 1/A, and under the consistent coupling SIMPLEC's 1 / (A - H1), H1 the sum of the neighbour
// coefficients: where the viscous coupling dominates, A - H1 leaves the transient term (and the
// walls' share). Floored at half the transient term, where the mass flux leaving a cell exceeds
// what enters. Only in cells that are mostly material: in the air next to it, 1 / (A - H1) is the
// light phase's dt / rho, a thousand times the material's, and the linear face value between the
// two made a flat layer at rest unstable (a round-off disturbance grew to 0.1 m/s in 0.3 s, test
// VofSolver.FlatLayerStaysAtRestWithTheConsistentCoupling); the air keeps 1/A.
void MomentumEqn::coefficients(const Fields& F, double dt) {
  const auto& A = UEqn_.A();
  parallel_each(region_.halo, [&](int c) { rAU[c] = m_.volume[c] / A[c]; });  // 1 / A per unit volume [m3 s/kg]
  region_.ranks().sync(rAU);
  parallel_each(region_.faces, [&](int f) { rAUf[f] = interpolate_or_owner(m_, f, rAU); });
  if (!cfg_.consistent) return;
  UEqn_.H1(m_, region_.cell_faces(), region_.face_in, region_.halo, H1_);
  parallel_each(region_.halo, [&](int c) {
    const double V = m_.volume[c];
    rAtU[c] = F.alpha[c] < cfg_.consistent_alpha ? rAU[c] : V / std::max(A[c] - H1_[c], 0.5 * F.rho[c] * V / dt);
  });
  region_.ranks().sync(rAtU);
  parallel_each(region_.faces, [&](int f) { rAtUf[f] = interpolate_or_owner(m_, f, rAtU); });
  if (column_) normal_coefficients(F, dt);
}

// Where the column friction's drag D acts, the coefficients along the bed normal leave it out:
// 1/(A - D) and 1/(A - D - H1) (the drag acts along the bed only); the faces take each cell's
// coefficient along their normal, interpolated as the scalar ones are.
void MomentumEqn::normal_coefficients(const Fields& F, double dt) {
  parallel_each(region_.halo, [&](int c) {
    const double D = drag_.drag[c], V = m_.volume[c];
    if (!(D > 0)) {
      drA[c] = drAt[c] = 0;
      return;
    }
    const double A0 = diag_no_drag_[c];
    drA[c] = V / A0 - rAU[c];
    if (cfg_.consistent)
      drAt[c] = F.alpha[c] < cfg_.consistent_alpha ? drA[c] : V / std::max(A0 - H1_[c], 0.5 * F.rho[c] * V / dt) - rAtU[c];
  });
  region_.ranks().sync(drA);
  if (cfg_.consistent) region_.ranks().sync(drAt);
  parallel_each(region_.faces, [&](int f) {
    const int o = m_.owner[f];
    const Vec& S = m_.Sf[f];
    auto along = [&](const CellField<double>& dr, int c) { return dr[c] != 0 ? dr[c] * sq_along(drag_.normal[c], S) : 0.0; };
    if (!internal(m_, f)) {
      rAUf[f] += along(drA, o);
      if (cfg_.consistent) rAtUf[f] += along(drAt, o);
      return;
    }
    const int nb = m_.neighbour[f];
    const double w = m_.weight[f];
    rAUf[f] += w * along(drA, o) + (1 - w) * along(drA, nb);
    if (cfg_.consistent) rAtUf[f] += w * along(drAt, o) + (1 - w) * along(drAt, nb);
  });
}

void MomentumEqn::update_HbyA(const Fields& F) {
  UEqn_.H(m_, region_.cell_faces(), region_.face_in, F.U, region_.halo, H_);
  parallel_each(region_.halo, [&](int c) { HbyA[c] = (1.0 / UEqn_.diag[c]) * H_[c]; });
  if (!column_) {
    region_.ranks().sync(HbyA);
    return;
  }
  // Where the column friction acts: (A along the bed, A - D along n)^-1 (H less the drag's explicit
  // part on the normal velocity), the momentum equation with the drag along the bed only.
  parallel_each(region_.halo, [&](int c) {
    const double D = drag_.drag[c];
    if (!(D > 0)) return;
    const double A = UEqn_.diag[c];
    const Vec h = H_[c] - drag_.given_back[c];
    const Vec& n = drag_.normal[c];
    HbyA[c] = (1.0 / A) * h + ((1.0 / diag_no_drag_[c] - 1.0 / A) * dot(n, h)) * n;
  });
  region_.ranks().sync(HbyA);
}

void MomentumEqn::unit_coefficients() {
  std::fill(rAUf.begin(), rAUf.end(), 1.0);
  std::fill(rAU.begin(), rAU.end(), 1.0);
  std::fill(HbyA.begin(), HbyA.end(), Vec{});
}

}  // namespace runout::engine::vof
