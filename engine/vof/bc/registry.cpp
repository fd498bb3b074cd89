// The boundary conditions by name. A new kind: its file in bc/ defining its factory, and one entry
// here (the factory's declaration and its row); PatchBc::type selects it by name. The Bc enum's
// kinds are the rows that carry one.
#include <array>
#include <optional>
#include <string_view>

#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/error.hpp"

namespace runout::engine::vof {

using MakeBc = std::unique_ptr<BoundaryCondition> (*)(const std::string& patch, const PatchBc& bc);

std::unique_ptr<BoundaryCondition> make_wall(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_coulomb_slip(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_atmosphere(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_inflow(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_outflow(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_symmetry(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_coulomb_friction(const std::string&, const PatchBc&);

namespace {

struct Entry {
  std::string_view name;
  std::optional<Bc> kind;
  MakeBc make;
};

const std::array kConditions = {
    Entry{"wall", Bc::wall, make_wall},
    Entry{"coulomb_slip", Bc::coulomb_slip, make_coulomb_slip},
    Entry{"atmosphere", Bc::atmosphere, make_atmosphere},
    Entry{"inflow", Bc::inflow, make_inflow},
    Entry{"outflow", Bc::outflow, make_outflow},
    Entry{"symmetry", Bc::symmetry, make_symmetry},
    Entry{"coulomb_friction", Bc::coulomb_friction, make_coulomb_friction},
};

}  // namespace

std::vector<std::string> boundary_condition_names() {
  std::vector<std::string> names;
  for (const auto& e : kConditions) names.emplace_back(e.name);
  return names;
}

std::unique_ptr<BoundaryCondition> make_boundary_condition(const std::string& patch, const PatchBc& bc) {
  for (const auto& e : kConditions)
    if (bc.type.empty() ? e.kind == bc.kind : e.name == bc.type) return e.make(patch, bc);
  std::string valid;
  for (const auto& e : kConditions) valid += (valid.empty() ? "" : ", ") + std::string(e.name);
  throw VofError("boundary conditions: patch '" + patch + "' has the unknown kind '" + bc.type + "' (valid: " + valid + ")");
}

}  // namespace runout::engine::vof
