#pragma once
// The phase-fraction equation (dissertation eqs. 4.51-4.53): alpha transported explicitly by the
// last face fluxes, upwind plus a correction toward the central value with interface compression
// (c_alpha), limited by Zalesak's flux-corrected transport so that every cell stays within its
// neighbours' bounds and [0, 1] (interFoam's MULES), in sub-cycles. Leaves the step's granular flux
// alpha_phi and the mass flux rho_phi. With VofConfig::settling_speed the granular phase also falls
// through the air along gravity (a monotone settling flux in the low-order part), with as many more
// sub-cycles as keep its Courant number at most 0.5.
#include "engine/vof/active_region.hpp"
#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/config.hpp"
#include "engine/vof/fields.hpp"

namespace runout::engine::vof {

class AlphaEqn {
 public:
  AlphaEqn(const Mesh& m, const VofConfig& cfg, const BcContext& bc_ctx, const Boundaries& bcs, const ActiveRegion& region,
           double mean_cell_size);
  void solve(Fields& F, double dt, const Vec& gravity);

 private:
  void interface_normal(const Fields& F);
  void fluxes_and_bounds(const Fields& F);
  void settling_fluxes(const Fields& F);
  int settling_subcycles(const Vec& gravity, double dt);
  void limit_and_update(Fields& F, double dts, int subcycles);

  const Mesh& m_;
  const VofConfig& cfg_;
  const BcContext& bc_ctx_;
  const Boundaries& bcs_;
  const ActiveRegion& region_;
  const double delta_n_;  // keeps the unit normal's division finite
  FaceField<double> FL_, AF_;  // low-order flux; antidiffusive flux (high-order less low-order), then its limited share of the step
  CellField<double> amax_, amin_, Rp_, Rm_, aL_;  // local bounds; Zalesak's ratios; alpha V
  CellField<Vec> grad_alpha_;
  Vec down_;  // g/|g| of this solve (settling on): the flux w down_.Sf per face
};

}  // namespace runout::engine::vof
