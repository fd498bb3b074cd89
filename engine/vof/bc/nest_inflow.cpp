// nest_inflow: the boundary of a nest inside another model's run (one-way coupling). In each step
// PatchBc::timed_inflow says, per face, whether the surrounding run's material enters there and
// with what velocity and fill: such a face is an inflow (its flux fixed, its cells computed, the
// shear of a wall moving with the inflow); every other face, and every face while nothing enters, is
// open to the still air as the atmosphere (air in at rest, anything out). The state is taken once
// per step (begin_step), so that every equation of the step sees the same faces open.
#include <vector>

#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/error.hpp"

namespace runout::engine::vof {

namespace {

class NestInflow final : public BoundaryCondition {
 public:
  NestInflow(const std::string& patch, const PatchBc& bc) : patch_(patch), source_(bc.timed_inflow) {}

  void begin_step(const BcContext& c) override {
    const Mesh& m = c.mesh;
    const Patch& p = m.patch(patch_);
    start_ = p.start;
    in_.assign(std::size_t(p.size), 0);
    U_.assign(std::size_t(p.size), Vec{});
    alpha_.assign(std::size_t(p.size), 0.0);
    for (int q = 0; q < p.size; ++q) {
      Vec u;
      double a = 0;
      if (source_(p.start + q, c.t0, c.t1, u, a) && dot(u, m.Sf[std::size_t(p.start + q)]) < 0) {  // into the domain
        in_[std::size_t(q)] = 1;
        U_[std::size_t(q)] = u;
        alpha_[std::size_t(q)] = a;
      }
    }
  }
  double alpha(const BcContext& c, int f) const override {
    if (entering(f)) return alpha_[std::size_t(f - start_)];
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
};

}  // namespace

std::unique_ptr<BoundaryCondition> make_nest_inflow(const std::string& patch, const PatchBc& bc) {
  if (!bc.timed_inflow) throw VofError("boundary conditions: nest_inflow patch '" + patch + "' needs its timed inflow (PatchBc::timed_inflow)");
  return std::make_unique<NestInflow>(patch, bc);
}

}  // namespace runout::engine::vof
