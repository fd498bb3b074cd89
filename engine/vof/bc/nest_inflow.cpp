// nest_inflow: the boundary of a nest inside another model's run (one-way coupling). In each step
// PatchBc::timed_inflow says, per face, whether the surrounding run's material enters there and
// with what velocity and fill: such a face is an inflow (its flux fixed, its cells computed, the
// shear of a wall moving with the inflow); every other face, and every face while nothing enters, is
// open to the still air as the atmosphere (air in at rest, anything out). The state is taken once
// per step (begin_step), so that every equation of the step sees the same faces open. The alpha
// equation carries the last pressure solve's fluxes (alpha_eqn.cpp): through a face that entered in
// that step the fill it entered with then (carried_alpha: the last step's state, kept; at the first
// step and after a restore taken again from the series for the step c.tp0-c.tp1, so that a run
// continued from a checkpoint takes the same). The series thus enters one
// step late: step n brings in the fill and flux of step n - 1 over its own length, and what enters
// differs from the series' volume by the sum over the faces of fill x flux x (the length of the
// first step that brings it in - the length of the step after the last one it enters in).
#include <algorithm>
#include <vector>

#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/error.hpp"

namespace runout::engine::vof {

namespace {

class NestInflow final : public BoundaryCondition {
 public:
  NestInflow(const std::string& patch, const PatchBc& bc) : patch_(patch), source_(bc.timed_inflow) {}

  void begin_step(const BcContext& c) override {
    const Patch& p = c.mesh.patch(patch_);
    start_ = p.start;
    if (c.tp0 == t0_ && c.tp1 == t1_ && in_.size() == std::size_t(p.size)) {  // the last step's state, taken then
      in_last_.swap(in_);
      alpha_last_.swap(alpha_);
    } else {  // the first step, or after a restore: take it again from the series
      std::vector<Vec> U_last;
      take(c.mesh, p, c.tp0, c.tp1, in_last_, U_last, alpha_last_);
    }
    take(c.mesh, p, c.t0, c.t1, in_, U_, alpha_);
    t0_ = c.t0, t1_ = c.t1;
  }
  double alpha(const BcContext& c, int f) const override {
    if (entering(f)) return alpha_[std::size_t(f - start_)];
    return c.fields.phi[f] < 0 ? 0.0 : c.fields.alpha[c.mesh.owner[f]];
  }
  double carried_alpha(const BcContext& c, int f) const override {
    const int q = f - start_;
    if (q >= 0 && std::size_t(q) < in_last_.size() && in_last_[std::size_t(q)]) return alpha_last_[std::size_t(q)];
    return c.fields.phi[f] < 0 ? 0.0 : c.fields.alpha[c.mesh.owner[f]];
  }
  Vec velocity(const BcContext& c, int f) const override {
    if (entering(f)) return U_[std::size_t(f - start_)];
    const Mesh& m = c.mesh;
    const double ph = c.fields.phi[f];
    return ph >= 0 ? c.fields.U[m.owner[f]] : (ph / m.magSf[f]) * unit_normal(m, f);
  }
  void momentum(const BcContext& c, int f, const Vec& Ub, double& diag, Vec& source) const override {
    if (entering(f)) wall_shear(c, f, Ub, c.wall_viscosity == WallViscosity::face, alpha(c, f), diag, source);
  }
  double predicted_flux(const BcContext& c, int f, const Vec& HbyA_o, bool initial) const override {
    if (entering(f)) return dot(U_[std::size_t(f - start_)], c.mesh.Sf[f]);
    return initial ? 0.0 : dot(HbyA_o, c.mesh.Sf[f]);
  }
  std::optional<double> fixed_flux(const BcContext& c, int f) const override {
    if (entering(f)) return dot(U_[std::size_t(f - start_)], c.mesh.Sf[f]);
    return std::nullopt;
  }
  bool opening() const override { return true; }
  bool opening_at(int f) const override { return !entering(f); }
  bool seeds_active_region() const override { return true; }
  bool seeds_active_region_at(int f) const override { return entering(f); }

 private:
  // The series' state of the patch's faces over t0-t1: which enter, with what velocity and fill.
  void take(const Mesh& m, const Patch& p, double t0, double t1, std::vector<std::uint8_t>& in, std::vector<Vec>& U,
            std::vector<double>& alpha) const {
    in.assign(std::size_t(p.size), 0);
    U.assign(std::size_t(p.size), Vec{});
    alpha.assign(std::size_t(p.size), 0.0);
    for (int q = 0; q < p.size; ++q) {
      Vec u;
      double a = 0;
      if (source_(p.start + q, t0, t1, u, a) && dot(u, m.Sf[std::size_t(p.start + q)]) < 0) {  // into the domain
        in[std::size_t(q)] = 1;
        U[std::size_t(q)] = u;
        alpha[std::size_t(q)] = a;
      }
    }
  }
  bool entering(int f) const {
    const int q = f - start_;
    return q >= 0 && std::size_t(q) < in_.size() && in_[std::size_t(q)];
  }
  std::string patch_;
  std::function<bool(int, double, double, Vec&, double&)> source_;
  int start_ = 0;
  std::vector<std::uint8_t> in_;
  std::vector<Vec> U_;
  std::vector<double> alpha_;
  std::vector<std::uint8_t> in_last_;  // the same over the step whose fluxes alpha is carried by
  std::vector<double> alpha_last_;
  double t0_ = -1, t1_ = -1;  // the step in_, U_ and alpha_ were taken for
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_nest_inflow(const std::string& patch, const PatchBc& bc) {
  if (!bc.timed_inflow) throw VofError("boundary conditions: nest_inflow patch '" + patch + "' needs its timed inflow (PatchBc::timed_inflow)");
  return std::make_unique<NestInflow>(patch, bc);
}

}  // namespace runout::engine::vof
