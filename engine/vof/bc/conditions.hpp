#pragma once
// The boundary conditions' rows: name, caption and what each does, and where a scenario may take it.
// The scenario's choices (lab.boundaries[].kind, vof.bed), the reference page and the maps read
// these rows; bc/registry.cpp makes each by its row's name. Header-only and free of the solver's
// libraries, so that the scenario library reads the rows without linking the solver.
//
// A new condition: one file in bc/ with its class and factory, its row here and its factory's line
// in bc/registry.cpp (a static_assert there keeps the two tables in the same order).
// tests/unit/test_example_models.cpp adds an example condition that is in neither table with
// add_boundary_condition (boundary.hpp).
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace runout::engine::vof {

struct BoundaryConditionRow {
  std::string_view name;     ///< PatchBc::type; scenarios spell it with '-' for '_'
  std::string_view caption;  ///< the condition on maps
  std::string_view doc;      ///< what it does (the reference page)
  bool bed = false;           ///< may be the ground of the 3D engine on the DEM (vof.bed)
  bool bed_friction = false;  ///< takes the bed friction angle (PatchBc::tan_delta)
  bool coupled = false;       ///< fed by another model at run time (a nest's boundary): no scenario names it
};

inline constexpr std::array<BoundaryConditionRow, 8> kBoundaryConditions{{
    {"wall", "stick wall", "no flow through it, no slip along it; its shear from the viscosity on the face", true, false},
    {"coulomb_slip", "Coulomb slip wall",
     "the material slides with the slip that makes the cell's shear carry tan(delta) p, and sticks where that shear exceeds it "
     "(listing B.2)",
     true, true},
    {"coulomb_friction", "Coulomb friction",
     "the bed's Coulomb friction as a force, tan(delta) p per area against the sliding velocity (docs/design/vof.md)", true, true},
    {"atmosphere", "atmosphere", "open to the still air outside (its total pressure): air flows in, anything flows out", false, false},
    {"outflow", "outflow", "zero gradient: material leaves freely", false, false},
    {"inflow", "inflow", "prescribed velocity and phase fraction, its cells always computed", false, false},
    {"symmetry", "symmetry", "no flow through it and no shear along it (a plane of symmetry, a frictionless wall)", false, false},
    {"nest_inflow", "coupled inflow",
     "a nest's boundary: the flow of the run around it enters where and while it enters, with its velocity and its fill of the "
     "face over the step; elsewhere open to the still air as the atmosphere",
     false, false, true},
}};

namespace detail {
inline std::vector<const BoundaryConditionRow*>& boundary_condition_rows() {
  static std::vector<const BoundaryConditionRow*> rows = [] {
    std::vector<const BoundaryConditionRow*> v;
    for (const auto& r : kBoundaryConditions) v.push_back(&r);
    return v;
  }();
  return rows;
}
}  // namespace detail

/// Every condition: the table's rows, then those added (add_boundary_condition, boundary.hpp).
inline const std::vector<const BoundaryConditionRow*>& boundary_conditions() { return detail::boundary_condition_rows(); }

/// The condition called `name` (PatchBc::type), or null.
inline const BoundaryConditionRow* find_boundary_condition(std::string_view name) {
  for (const auto* r : boundary_conditions())
    if (r->name == name) return r;
  return nullptr;
}

/// The name as scenarios spell it: '-' for '_' ("coulomb-slip").
inline std::string scenario_spelling(std::string_view name) {
  std::string s(name);
  for (char& ch : s)
    if (ch == '_') ch = '-';
  return s;
}

}  // namespace runout::engine::vof
