// The boundary conditions by name: the factory of each row of bc/conditions.hpp, in the rows' order
// (a static_assert checks it), and those added with add_boundary_condition. PatchBc::type selects
// one by name; the Bc enum's kinds are the rows that carry one.
#include <array>
#include <optional>
#include <string_view>

#include "engine/vof/bc/boundary.hpp"
#include "engine/vof/bc/conditions.hpp"
#include "engine/vof/error.hpp"

namespace runout::engine::vof {

std::unique_ptr<BoundaryCondition> make_wall(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_coulomb_slip(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_atmosphere(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_inflow(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_outflow(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_symmetry(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_coulomb_friction(const std::string&, const PatchBc&);
std::unique_ptr<BoundaryCondition> make_nest_inflow(const std::string&, const PatchBc&);

namespace {

struct Entry {
  std::string_view name;
  std::optional<Bc> kind;
  MakeBc make;
};

constexpr std::array kConditions = {
    Entry{"wall", Bc::wall, make_wall},
    Entry{"coulomb_slip", Bc::coulomb_slip, make_coulomb_slip},
    Entry{"coulomb_friction", Bc::coulomb_friction, make_coulomb_friction},
    Entry{"atmosphere", Bc::atmosphere, make_atmosphere},
    Entry{"outflow", Bc::outflow, make_outflow},
    Entry{"inflow", Bc::inflow, make_inflow},
    Entry{"symmetry", Bc::symmetry, make_symmetry},
    Entry{"nest_inflow", std::nullopt, make_nest_inflow},
};

constexpr bool same_order() {
  if (kConditions.size() != kBoundaryConditions.size()) return false;
  for (std::size_t k = 0; k < kConditions.size(); ++k)
    if (kConditions[k].name != kBoundaryConditions[k].name) return false;
  return true;
}
static_assert(same_order(), "bc/registry.cpp: one factory per row of bc/conditions.hpp, in its order");

// The factories of the conditions added to the rows (add_boundary_condition).
std::vector<std::pair<std::string, MakeBc>>& added() {
  static std::vector<std::pair<std::string, MakeBc>> v;
  return v;
}

}  // namespace

std::vector<std::string> boundary_condition_names() {
  std::vector<std::string> names;
  for (const auto* r : boundary_conditions()) names.emplace_back(r->name);
  return names;
}

bool add_boundary_condition(const BoundaryConditionRow& row, MakeBc make) {
  if (find_boundary_condition(row.name)) throw VofError("boundary conditions: a condition '" + std::string(row.name) + "' is already registered");
  detail::boundary_condition_rows().push_back(&row);
  added().emplace_back(std::string(row.name), make);
  return true;
}

std::unique_ptr<BoundaryCondition> make_boundary_condition(const std::string& patch, const PatchBc& bc) {
  for (const auto& e : kConditions)
    if (bc.type.empty() ? e.kind == bc.kind : e.name == bc.type) return e.make(patch, bc);
  for (const auto& [name, make] : added())
    if (name == bc.type) return make(patch, bc);
  throw VofError("boundary conditions: patch '" + patch + "' has the unknown kind '" + bc.type + "' (valid: " + [] {
    std::string valid;
    for (const auto& name : boundary_condition_names()) valid += (valid.empty() ? "" : ", ") + name;
    return valid;
  }() + ")");
}

}  // namespace runout::engine::vof
