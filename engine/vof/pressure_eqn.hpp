#pragma once
// The pressure equation (dissertation eqs. 4.59-4.63), one PISO corrector as interFoam's pEqn.H:
//   phiHbyA = flux(H/A) + phig,  phig = -ghf snGrad(rho) rAUf |Sf|,
//   laplacian(rAUf, p_rgh) = div(phiHbyA)          over the active region,
//   phi = phiHbyA + pEqn.flux(),  U = H/A + rAU reconstruct((phig + pEqn.flux()) / rAUf),
// with the faces to the still air outside (the atmosphere, the edge of the active region) as
// openings at the outside's pressure, SIMPLEC's coefficients under the consistent coupling, and in
// a closed domain the level fixed at its highest cell.
#include "engine/vof/active_region.hpp"
#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/config.hpp"
#include "engine/vof/fields.hpp"
#include "engine/vof/fv/fv_matrix.hpp"
#include "engine/vof/linear/petsc.hpp"
#include "engine/vof/momentum_eqn.hpp"

namespace runout::engine::vof {

/// Which corrector PressureEqn::correct() runs, by name at the call.
struct CorrectorPass {
  bool initial = false;  ///< the initial hydrostatic solve (no velocity)
  /// A later corrector of the step (1/A, the density and the region unchanged: the matrix and its
  /// coefficients are kept).
  bool reuse = false;
  bool final = false;  ///< the step's last corrector (its tolerance)
};

class PressureEqn {
 public:
  PressureEqn(const Mesh& m, const VofConfig& cfg, const BcContext& bc_ctx, const Boundaries& bcs, const ActiveRegion& region,
              const Reconstruction& reconstruct, PressureSolver& solver);
  /// (Re)create the pressure system for the current active region.
  void make_system();
  /// One corrector (CorrectorPass): solve for p_rgh and correct the fluxes and velocities. Returns
  /// the iterations.
  int correct(Fields& F, const MomentumEqn& UEqn, CorrectorPass pass, double t);

 private:
  struct Coupling {  // the coefficients of this corrector: 1/A (PISO) or 1/(A - H1) (SIMPLEC)
    bool consistent;
    const FaceField<double>& rAf;
    const MomentumEqn& U;  // the cells' coefficients along a direction (rA_along, rA_apply; the column friction's drag acts along the bed only)
  };
  void laplacian_coefficients(const Fields& F, const Coupling& k);
  void predicted_flux(const MomentumEqn& UEqn, bool initial, const Coupling& k);
  void assemble(const Fields& F, bool reuse);
  void correct_flux_and_velocity(Fields& F, const MomentumEqn& UEqn, bool initial, const Coupling& k);
  void fix_level(Fields& F);
  // The non-orthogonal correction (VofConfig::n_non_orthogonal_correctors): the Gauss gradient of p
  // over the active region, and per face its part of the face force with gravity's, limited.
  void pressure_correction(const Fields& F, const Coupling& k);
  void pressure_gradient(const Fields& F, const CellField<double>& p, CellField<Vec>& out) const;

  const Mesh& m_;
  const VofConfig& cfg_;
  const BcContext& bc_ctx_;
  const Boundaries& bcs_;
  const ActiveRegion& region_;
  const Reconstruction& reconstruct_;
  PressureSolver& solver_;
  // The Laplacian per cell and face (upper: its coefficient on every face of the region, openings
  // included); diag and source (the right-hand side) per cell.
  FvMatrix<double> pEqn_;
  // Per face: the flux predicted from H/A (oriented with Sf), its buoyancy part, and for an opening
  // (atmosphere patch or the edge of the active region) the side of the active cell (+1 owner, -1
  // neighbour) and the pressure outside.
  FaceField<double> phiHbyA_, phig_, pout_;
  FaceField<double> pcorr_;  // the non-orthogonal part of the pressure flux (0 without correctors)
  CellField<Vec> grad_;      // the Gauss gradient of p (the non-orthogonal correction's)
  CellField<double> p_now_;  // p from the latest p_rgh
  FaceField<signed char> open_;
  CellField<Vec> rec_, rec_old_;  // sums of face forces times Sf for the reconstruction
  FaceField<double> w_;            // per face: the force it gives its active cells (gather_face_forces)
  void gather_face_forces(CellField<Vec>& rec) const;
  std::vector<double> diag_rows_, rhs_rows_, x_rows_;
};

}  // namespace runout::engine::vof
