#pragma once
// The momentum equation (dissertation eqs. 4.54-4.58), as interFoam's UEqn:
//   ddt(rho, U) + div(rho_phi, U) - laplacian(mu_f, U) = div(mu_f (grad U)^T) + boundary terms,
// Euler implicit, upwind convection of the mass flux (optionally limitedLinearV as a deferred
// correction), the viscous term implicit with the linear face viscosity and its transpose part
// explicit. It yields 1/A and H/A for the pressure equation (PISO: 1/A; SIMPLEC under
// VofConfig::consistent: 1/(A - H1) in the material) and, optionally, the momentum predictor.
// Also the velocity gradient and the viscosities it takes.
#include "engine/vof/active_region.hpp"
#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/column_friction.hpp"
#include "engine/vof/config.hpp"
#include "engine/vof/fields.hpp"
#include "engine/vof/fv/fv_matrix.hpp"
#include "engine/vof/linear/petsc.hpp"

namespace runout::engine::vof {

class MomentumEqn {
 public:
  MomentumEqn(const Mesh& m, const VofConfig& cfg, const BcContext& bc_ctx, const Boundaries& bcs, const ActiveRegion& region,
              const Reconstruction& reconstruct, int dims);
  /// The momentum predictor's solver.
  void setup_predictor();

  /// The Gauss gradient of the velocity per cell into F.gradU (boundary values from the
  /// conditions; only faces of the active region contribute, the air beyond rests).
  void velocity_gradient(Fields& F) const;
  /// The gradient, then the granular viscosity and the mixture viscosity of the active cells.
  void update_viscosity(Fields& F) const;

  /// The matrix from the current fields (once per step and outer corrector), and its 1/A.
  void build(const Fields& F, double dt);
  /// H/A from the current velocity (every corrector).
  void update_HbyA(const Fields& F);
  /// Solve the matrix with the last pressure's and the buoyancy's force; returns the iterations.
  int predict(Fields& F, double t);
  /// For the initial hydrostatic solve: unit 1/A and no H/A.
  void unit_coefficients();

  const FvMatrix<Vec>& matrix() const { return UEqn_; }
  CellField<double> rAU, rAtU;   ///< 1/A per unit volume [m3 s/kg]; the consistent coupling's 1/(A - H1)
  FaceField<double> rAUf, rAtUf; ///< the same on the faces
  CellField<Vec> HbyA;
  /// Where the column friction acts (VofConfig::column_friction) its drag holds the velocity along
  /// the bed only, so the coefficients along the bed normal n are those without it: larger by drA
  /// (1/A) and drAt (1/(A - H1)) per unit volume; zero elsewhere. A face or a vector takes the
  /// coefficient r + dr (s.n)^2 along its unit normal s, r v + dr (n.v) n (docs/design/vof.md).
  CellField<double> drA, drAt;
  /// 1/A (consistent: 1/(A - H1)) of cell c along the direction of s.
  double rA_along(bool consistent, int c, const Vec& s) const;
  /// 1/A (consistent: 1/(A - H1)) of cell c applied to v.
  Vec rA_apply(bool consistent, int c, const Vec& v) const;
  /// (1/A - 1/(A - H1)) of cell c applied to v.
  Vec rA_difference_apply(int c, const Vec& v) const;
  BedLoad bed_load;  ///< the column friction's loads at the last build (VofConfig::column_friction)

 private:
  void transient(const Fields& F, double dt);
  void transpose_stress(const Fields& F);
  void convection_diffusion(const Fields& F);
  void limited_linear_correction(const Fields& F);
  void boundary_terms(const Fields& F);
  void side_wall_friction(const Fields& F);
  void coefficients(const Fields& F, double dt);
  void normal_coefficients(const Fields& F, double dt);
  void predictor_forces();
  void predictor_rows(const Fields& F);

  const Mesh& m_;
  const VofConfig& cfg_;
  const BcContext& bc_ctx_;
  const Boundaries& bcs_;
  const ActiveRegion& region_;
  const Reconstruction& reconstruct_;
  const int dims_;
  FvMatrix<Vec> UEqn_;
  CellField<Vec> H_;
  CellField<double> H1_;
  CellField<Vec> force_;          // the predictor's force
  ColumnDrag drag_;               // the column friction's drag per cell (sized when it acts)
  CellField<double> diag_no_drag_;  // the diagonal before the drag was added
  bool column_ = false;
  FaceField<double> diag_o_, diag_n_;  // per face: what it adds to its owner's and neighbour's diagonal
  FaceField<Vec> face_vec_;       // per face: the transpose stress it gives its cells
  std::vector<int> rows_, row_of_;  // the predicted cells (ascending); per cell its row or -1
  int n_own_rows_ = 0;               // the rank's own rows (the first of rows_; all of them on one process)
  long long total_rows_ = 0;
  std::vector<int> global_of_;       // split over ranks: per cell its row in the whole system, or -1
  std::vector<Vec> known_;        // per row: the share of the neighbours that are not predicted
  CsrMatrix A_;
  MomentumSolver solver_;
};

}  // namespace runout::engine::vof
