#pragma once
// Inside jobs/scenario: the mu(I) rheology's fields, which the laboratory block (lab.*) and the
// material block (material.*) spell alike, and the law's checks as a scenario error.
#include <string>

#include "engine/vof/models/mu_i_law.hpp"
#include "jobs/scenario/scenario_impl.hpp"

namespace runout::jobs {

/// The mu(I) parameters that `msg` (v1::Lab or v1::Material) sets; the others stay as they are.
template <class Msg>
void take_mu_i_fields(const Msg& msg, engine::vof::VofConfig::MuI& m) {
  if (msg.has_mu_s()) m.mu_s = msg.mu_s();
  if (msg.has_mu_2()) m.mu_2 = msg.mu_2();
  if (msg.has_mu_i0()) m.i0 = msg.mu_i0();
  if (msg.has_grain_diameter_m()) m.grain_diameter = msg.grain_diameter_m();
  if (msg.has_grain_density_kg_m3()) m.grain_density = msg.grain_density_kg_m3();
}

/// The law's own checks and, regularised, the join of its branches (MuILaw checks and joins when
/// built): a failure is a ScenarioError naming `field`.
inline void check_mu_i_law(const engine::vof::VofConfig& c, bool regularised, const std::string& field) {
  try {
    const engine::vof::MuILaw law(c.mu_i, c.rho1, regularised);
    (void)law;
  } catch (const engine::vof::VofError& e) {
    bad(field, e.what());
  }
}

}  // namespace runout::jobs
