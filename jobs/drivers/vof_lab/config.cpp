#include "jobs/drivers/vof_lab/config.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::vof_lab {

namespace {

namespace vof = engine::vof;
constexpr double kPi = 3.14159265358979323846;

// The value of option `field` from the engine's name table; "" is `fallback` (the option's default).
// The option table has checked the name already; a name it let through would be an error here.
template <class E, std::size_t N>
E choose(const std::string& value, const char* field, const engine::NameTable<E, N>& table, E fallback) {
  if (value.empty()) return fallback;
  try {
    return engine::parse_name(table, field, value);
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(std::string(field) + ": " + e.what());
  }
}

// lab.bed_normal_stress "column": the friction of the bottom's coulomb-friction parts on the weight
// of the material in the cells above each of their faces (engine/vof/column_friction.hpp), as the
// terrain runs take it; those parts then take no shear (symmetry), so that it is counted once.
// Other coulomb-friction sides (the walls of a 3D box, an obstacle) keep the load of their face's
// pressure: their columns would run along the channel or cross the bottom's.
void take_column_load(const Material& mat, const vof::Mesh& m, vof::VofConfig& c) {
  std::vector<int> faces;
  for (auto& [name, pb] : c.bc) {
    if (pb.type != "coulomb_friction" || name.rfind("bottom", 0) != 0) continue;
    const auto& p = m.patch(name);
    for (int f = p.start; f < p.start + p.size; ++f) faces.push_back(f);
    pb.type = "symmetry";
  }
  if (faces.empty()) throw ScenarioError("lab.bed_normal_stress \"column\": no part of the bottom is coulomb-friction (lab.boundaries)");
  try {
    c.column_friction.columns = vof::columns_above(m, faces);
  } catch (const vof::VofError& e) {
    throw ScenarioError(std::string("lab.bed_normal_stress \"column\": ") + e.what());
  }
  c.column_friction.tan_delta = std::tan(mat.delta_deg * kPi / 180);
}

}  // namespace

Material lab_material(const v1::Lab& L) {
  const LabMaterial& m = jobs::lab_material(L.material());  // the option table's materials (validation.md part B)
  Material mat{m.rho, m.phi_deg, m.delta_deg};
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
  c.viscous_transpose = choose(L.viscous_transpose(), "lab.viscous_transpose", vof::kTransposeNames, vof::Transpose::harmonic);
  c.momentum_convection = choose(L.momentum_convection(), "lab.momentum_convection", vof::kConvectionNames, vof::Convection::upwind);
  c.coulomb_pressure = choose(L.coulomb_pressure(), "lab.coulomb_pressure", vof::kCoulombPressureNames, vof::CoulombPressure::total);
  c.wall_viscosity = choose(L.wall_viscosity(), "lab.wall_viscosity", vof::kWallViscosityNames, vof::WallViscosity::face);
  apply_lab_rheology(L, c);  // checked when the scenario was resolved
  if (!L.pressure_preconditioner().empty()) c.pressure_pc = L.pressure_preconditioner();
  c.active_layers = L.active_layers() < 0 ? 0 : L.active_layers();
  c.consistent = c.momentum_predictor = choose(L.pressure_coupling(), "lab.pressure_coupling", vof::kPressureCouplingNames, false);
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
    // The engine's registry finds the condition by name (engine/vof/bc/registry.cpp); scenarios
    // spell its names with '-' for '_'.
    pb.type = lb.kind().empty() ? "wall" : lb.kind();
    std::replace(pb.type.begin(), pb.type.end(), '-', '_');
    if (pb.type == "inflow") {
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
  if (L.bed_normal_stress() == "column") take_column_load(mat, m, c);
}

}  // namespace runout::jobs::vof_lab
