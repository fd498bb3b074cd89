#pragma once
// Boundary conditions of the VOF engine: one class per kind behind BoundaryCondition, made by name
// in bc/registry.cpp (VofConfig::bc gives each patch a PatchBc). The equations ask a face's
// condition for what it fixes, as OpenFOAM's patch fields answer the matrix assembly:
//   alpha()          the phase fraction on the face;
//   velocity()       the velocity on the face (for the gradient, the convection and the shear);
//   momentum()       its terms in the momentum matrix's row of the cell next to it (the shear of a
//                    wall, a friction force), before the convection through the face;
//   predicted_flux() the face's flux before the pressure correction (a fixed flux, zero through a
//                    wall, or the cell's H/A where the pressure sets it);
//   opening()        whether the face opens to the still air outside: the pressure equation fixes
//                    p_rgh there, it sets the reference level and joins the air reservoir;
//   seeds_active_region() whether the cell next to it is always computed (material enters there).
// A new kind: one file in bc/ with its class and factory, its row in bc/conditions.hpp (name,
// caption, what it does) and its factory's line in bc/registry.cpp.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/vof/fields.hpp"
#include "engine/vof/hydrostatics.hpp"
#include "engine/vof/mixture.hpp"
#include "engine/vof/models/granular_viscosity.hpp"
#include "engine/vof/config.hpp"

namespace runout::engine::vof {

/// What the boundary conditions read: the mesh, the fields and the models.
struct BcContext {
  const Mesh& mesh;
  const Fields& fields;
  const Hydrostatics& hydrostatics;
  const GranularViscosity& viscosity;
  const Mixture& mixture;
  WallViscosity wall_viscosity;
  double t0 = 0, t1 = 0;  ///< the step being taken (begin_step): from t0 to t1
  /// The step whose pressure solve gave the fluxes the alpha equation carries in this one: the last
  /// step, or at the start the initial pressure's instant (tp0 = tp1).
  double tp0 = 0, tp1 = 0;
};

class BoundaryCondition {
 public:
  virtual ~BoundaryCondition() = default;
  /// The phase fraction on boundary face f (default: zero gradient, the cell's).
  virtual double alpha(const BcContext& c, int f) const { return c.fields.alpha[c.mesh.owner[f]]; }
  /// The phase fraction that enters through face f with the last pressure solve's flux, which the
  /// alpha equation carries (default: alpha()). A condition whose fixed flux changes from step to
  /// step gives the fill that went with that flux (its state in the step c.tp0-c.tp1).
  virtual double carried_alpha(const BcContext& c, int f) const { return alpha(c, f); }
  /// The velocity on boundary face f.
  virtual Vec velocity(const BcContext& c, int f) const = 0;
  /// Its terms in the momentum matrix's row of the cell next to f (diagonal and source), with the
  /// face's velocity Ub (default: none).
  virtual void momentum(const BcContext& c, int f, const Vec& Ub, double& diag, Vec& source) const;
  /// The flux through f before the pressure correction; HbyA_o the cell's H/A, initial: the
  /// initial hydrostatic solve, with no velocity (default: none through the face).
  virtual double predicted_flux(const BcContext& c, int f, const Vec& HbyA_o, bool initial) const;
  /// A flux the condition fixes from the start (an inflow's), if any.
  virtual std::optional<double> fixed_flux(const BcContext&, int) const { return std::nullopt; }
  /// Whether the condition may open to the still air outside (the pressure there is the still air's).
  virtual bool opening() const { return false; }
  /// Whether boundary face f is open to the still air in the step being taken (default: opening()).
  virtual bool opening_at(int) const { return opening(); }
  /// Before each step (and before the initial pressure) with the step's times in c: a condition
  /// that changes in time takes its state for the step here.
  virtual void begin_step(const BcContext&) {}
  /// The cell next to it may belong to the active region for its sake (material may enter there).
  virtual bool seeds_active_region() const { return false; }
  /// The cell next to boundary face f belongs to the active region in the step being taken
  /// (default: seeds_active_region(); a coupled inflow: while material enters there).
  virtual bool seeds_active_region_at(int) const { return seeds_active_region(); }
};

/// The condition `patch`'s PatchBc names (PatchBc::type, or its kind); throws VofError for an
/// unknown name (listing the valid ones) or an incomplete PatchBc.
std::unique_ptr<BoundaryCondition> make_boundary_condition(const std::string& patch, const PatchBc& bc);

struct BoundaryConditionRow;
using MakeBc = std::unique_ptr<BoundaryCondition> (*)(const std::string& patch, const PatchBc& bc);
/// Adds a condition outside the tables (a test's example, a program's own condition): its row to
/// the rows every reader sees (bc/conditions.hpp) and its factory here; call it before the rows are
/// read (at start-up). Returns true; a name already taken is a VofError.
bool add_boundary_condition(const BoundaryConditionRow& row, MakeBc make);

// Shared by the wall-like conditions.

/// The mixture viscosity on boundary face f with the face's velocity Ub and phase fraction
/// alpha_b, as OpenFOAM evaluates a strain-rate-dependent viscosity on a patch: the strain rate
/// from the cell's gradient with its normal part replaced by the face's (Ub - U_o) / d
/// (gaussGrad's boundary correction), the pressure the face's (wall_pressure).
double boundary_mu(const BcContext& c, int f, const Vec& Ub, double alpha_b);
/// The viscous shear of a face whose velocity Ub is fixed (walls, inflows): mu |Sf| / d (Ub - U_P),
/// implicit in U_P; mu the face's (boundary_mu, face_viscosity) or the cell's.
void wall_shear(const BcContext& c, int f, const Vec& Ub, bool face_viscosity, double alpha_b, double& diag, Vec& source);

}  // namespace runout::engine::vof

namespace runout::engine::vof {

/// Every boundary face's condition, from VofConfig::bc by patch name.
class Boundaries {
 public:
  /// Throws VofError for a patch without a condition or a condition without a patch.
  Boundaries(const Mesh& m, const std::map<std::string, PatchBc>& bc);
  /// The condition of boundary face f.
  const BoundaryCondition& operator[](int f) const { return *face_[f - n_internal_]; }
  /// Whether any patch opens to the atmosphere (then the pressure level is fixed).
  bool has_opening() const { return has_opening_; }
  /// Every condition's begin_step with the step's times in c.
  void begin_step(const BcContext& c) {
    for (auto& b : conditions_) b->begin_step(c);
  }

 private:
  int n_internal_ = 0;
  std::vector<std::unique_ptr<BoundaryCondition>> conditions_;  // per patch
  std::vector<const BoundaryCondition*> face_;                  // per boundary face
  bool has_opening_ = false;
};

}  // namespace runout::engine::vof
