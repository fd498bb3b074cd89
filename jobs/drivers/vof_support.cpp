#include "jobs/drivers/vof_support.hpp"

#include <petscsys.h>

#include <algorithm>
#include <cmath>

namespace runout::jobs {

std::mutex& petsc_turn() {
  static std::mutex m;
  return m;
}

std::string petsc_options() {
  PetscBool started = PETSC_FALSE;
  PetscInitialized(&started);
  if (!started) return {};
  char* all = nullptr;
  if (PetscOptionsGetAll(nullptr, &all) != 0 || !all) return {};
  std::string s(all);
  PetscFree(all);
  return s;
}

}  // namespace runout::jobs
