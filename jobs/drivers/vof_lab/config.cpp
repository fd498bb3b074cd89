#include "jobs/drivers/vof_lab/config.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_lab {

namespace {

namespace vof = engine::vof;
constexpr double kPi = 3.14159265358979323846;

// The value of option `field` from its table; "" is `fallback` (the option's default).
template <class T>
T choose(const std::string& value, const char* field, const std::vector<std::pair<const char*, T>>& table, T fallback) {
  if (value.empty()) return fallback;
  std::string valid;
  for (const auto& [name, v] : table) {
    if (value == name) return v;
    valid += (valid.empty() ? "" : ", ") + std::string(name);
  }
  throw ScenarioError(std::string(field) + ": unknown '" + value + "' (valid: " + valid + ")");
}

}  // namespace

Material lab_material(const v1::Lab& L) {
  // validation.md part B; fine-sand: the rotating box, whose side walls raise the effective phi.
  Material mat = choose<Material>(L.material(), "lab.material",
                                  {{"pvc", {936.17, 32, 20}}, {"sand", {1626.67, 37, 18}}, {"fine-sand", {1855, 54.5, 54.5}}},
                                  {936.17, 32, 20});
  if (L.has_phi_deg()) mat.phi_deg = L.phi_deg();
  if (L.has_bed_friction_deg()) mat.delta_deg = L.bed_friction_deg();
  return mat;
}

vof::VofConfig lab_config(const v1::Lab& L, const Material& mat) {
  vof::VofConfig c;
  c.rho1 = mat.rho;
  c.phi_deg = mat.phi_deg;
  c.max_co = c.max_alpha_co = L.max_courant();
  c.n_correctors = L.correctors();
  c.n_outer_correctors = L.has_outer_correctors() ? L.outer_correctors() : 1;
  c.viscous_transpose = choose<vof::Transpose>(
      L.viscous_transpose(), "lab.viscous_transpose",
      {{"off", vof::Transpose::off}, {"explicit", vof::Transpose::linear}, {"harmonic", vof::Transpose::harmonic}}, vof::Transpose::harmonic);
  c.momentum_convection = choose<vof::Convection>(L.momentum_convection(), "lab.momentum_convection",
                                                  {{"upwind", vof::Convection::upwind}, {"limited_linear", vof::Convection::limited_linear}},
                                                  vof::Convection::upwind);
  c.coulomb_pressure = choose<vof::CoulombPressure>(L.coulomb_pressure(), "lab.coulomb_pressure",
                                                    {{"total", vof::CoulombPressure::total}, {"excess", vof::CoulombPressure::excess}},
                                                    vof::CoulombPressure::total);
  c.wall_viscosity = choose<vof::WallViscosity>(L.wall_viscosity(), "lab.wall_viscosity",
                                                {{"face", vof::WallViscosity::face}, {"cell", vof::WallViscosity::cell}}, vof::WallViscosity::face);
  if (!L.pressure_preconditioner().empty()) c.pressure_pc = L.pressure_preconditioner();
  c.active_layers = L.active_layers() < 0 ? 0 : L.active_layers();
  c.consistent = c.momentum_predictor =
      choose<bool>(L.pressure_coupling(), "lab.pressure_coupling", {{"piso", false}, {"consistent", true}}, false);
  const double zeta = L.inclination_deg() * kPi / 180;
  const double omega = L.rotation_period_s() > 0 ? 2 * kPi / L.rotation_period_s() : 0.0;
  c.gravity = [zeta, omega](double t) {
    // In the frame of a channel turning at omega (counter-clockwise), gravity turns clockwise.
    const double a = zeta + omega * t;
    return vof::Vec{9.81 * std::sin(a), -9.81 * std::cos(a), 0};
  };
  return c;
}

void apply_boundaries(const v1::Lab& L, const Material& mat, vof::Mesh& m, vof::VofConfig& c) {
  // Listed parts of sides become their own patches; the rest stays wall.
  for (const char* side : {"bottom", "top", "left", "right", "back", "front", "obstacle"})
    if (m.patch_index(side) >= 0) c.bc[side].kind = vof::Bc::wall;
  for (int k = 0; k < L.boundaries_size(); ++k) {
    const auto& lb = L.boundaries(k);
    const std::string field = "lab.boundaries[" + std::to_string(k) + "]";
    const std::string name = lb.side() + "-" + std::to_string(k);
    const bool along_x = lb.side() != "left" && lb.side() != "right";
    const double from = lb.has_from() ? lb.from() : -1e300, to = lb.has_to() ? lb.to() : 1e300;
    if (m.patch_index(lb.side()) < 0) throw ScenarioError(field + ": side " + lb.side() + " is already taken");
    vof::split_patch(m, lb.side(), name, [&](const vof::Vec& cf) {
      const double u = along_x ? cf.x : cf.y;
      return u >= from && u <= to;
    });
    if (m.patch_index(name) < 0) throw ScenarioError(field + ": no face of side " + lb.side() + " lies in [from, to]");
    vof::PatchBc pb;
    pb.kind = choose<vof::Bc>(lb.kind(), (field + ".kind").c_str(),
                              {{"wall", vof::Bc::wall},
                               {"atmosphere", vof::Bc::atmosphere},
                               {"outflow", vof::Bc::outflow},
                               {"coulomb-slip", vof::Bc::coulomb_slip},
                               {"coulomb-friction", vof::Bc::coulomb_friction},
                               {"inflow", vof::Bc::inflow},
                               {"symmetry", vof::Bc::symmetry}},
                              vof::Bc::wall);
    if (pb.kind == vof::Bc::inflow) {
      const double u0 = lb.inflow_u0(), dudy = lb.inflow_dudy(), hin = lb.inflow_height(), ybase = L.y_min();
      // Material below the fill height with the profile; air above enters at rest (appendix A.4:
      // "else (0, 0)").
      pb.inflow_velocity = [=](const vof::Vec& cf) { return cf.y - ybase < hin ? vof::Vec{u0 + dudy * (cf.y - ybase), 0, 0} : vof::Vec{}; };
      pb.inflow_alpha = [=](const vof::Vec& cf) { return cf.y - ybase < hin ? 1.0 : 0.0; };
    }
    pb.tan_delta = std::tan(mat.delta_deg * kPi / 180);
    c.bc[name] = pb;
  }
  for (auto it = c.bc.begin(); it != c.bc.end();)  // sides wholly taken by listed parts
    it = m.patch_index(it->first) < 0 ? c.bc.erase(it) : std::next(it);
}

}  // namespace runout::jobs::vof_lab
