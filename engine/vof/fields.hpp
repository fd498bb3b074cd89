#pragma once
// The VOF engine's fields in one place: the solution (alpha, U, p_rgh, p, the face flux phi), the
// quantities derived from it (density, viscosities, the velocity gradient, the mass and granular
// fluxes) and the old-time values the transient term takes.
#include "engine/vof/fv/field.hpp"
#include "engine/vof/fv/ops.hpp"
#include "engine/vof/mesh.hpp"

namespace runout::engine::vof {

struct Fields {
  CellField<double> alpha;  ///< granular phase fraction
  CellField<Vec> U;         ///< velocity
  CellField<double> p_rgh;  ///< p - rho g.x
  CellField<double> p;      ///< full pressure [Pa]
  CellField<double> nu1;    ///< granular-phase kinematic viscosity [m2/s]
  FaceField<double> phi;    ///< volume flux per face [m3/s], along Sf

  CellField<double> rho, rho_old;  ///< mixture density, now and at the step's start
  CellField<Vec> U_old;            ///< velocity at the step's start
  CellField<double> mu;            ///< mixture dynamic viscosity
  CellField<Tensor> gradU;         ///< velocity gradient
  FaceField<double> alpha_phi;     ///< granular volume flux over the last step (limited)
  FaceField<double> rho_phi;       ///< mass flux

  void resize(int cells, int faces, double nu_max) {
    const auto nc = std::size_t(cells), nf = std::size_t(faces);
    alpha.assign(nc, 0);
    p_rgh.assign(nc, 0);
    p.assign(nc, 0);
    nu1.assign(nc, nu_max);
    U.assign(nc, Vec{});
    phi.assign(nf, 0);
    rho.assign(nc, 0);
    rho_old = rho;
    mu = rho;
    U_old.assign(nc, Vec{});
    gradU.assign(nc, Tensor{});
    alpha_phi.assign(nf, 0);
    rho_phi = alpha_phi;
  }
};

}  // namespace runout::engine::vof
