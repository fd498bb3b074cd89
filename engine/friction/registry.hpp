#pragma once
// The depth-averaged engines' friction laws, found by name: one line per law.
#include <array>
#include <stdexcept>
#include <string>
#include <string_view>

#include "engine/friction/coulomb.hpp"
#include "engine/friction/mu_i.hpp"
#include "engine/friction/pouliquen_forterre.hpp"
#include "engine/friction/voellmy.hpp"

namespace runout::engine {

inline constexpr std::array<const FrictionLaw*, 4> kFrictionLaws{
    &friction::coulomb,
    &friction::voellmy,
    &friction::pouliquen_forterre,
    &friction::mu_i,
};

/// The law called `name`; an unknown name throws std::invalid_argument listing the valid ones.
inline const FrictionLaw& friction_law(std::string_view name) {
  std::string valid;
  for (const FrictionLaw* law : kFrictionLaws) {
    if (law->name == name) return *law;
    valid += (valid.empty() ? "" : ", ") + std::string(law->name);
  }
  throw std::invalid_argument("unknown friction law '" + std::string(name) + "' (valid: " + valid + ")");
}

}  // namespace runout::engine
