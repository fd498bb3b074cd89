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

double next_multiple(double interval, double t) { return interval * (std::floor(t / interval + 1e-9) + 1); }

bool report_step(const RunOptions& opt, const engine::vof::StepStats& st, long steps, int cells) {
  if (!opt.progress || steps % std::max(1L, opt.progress_every) != 0) return true;
  engine::Progress p;
  p.t = st.t;
  p.dt = st.dt;
  p.mass = st.granular_volume;
  p.max_speed = st.max_speed;
  p.active_fraction = double(st.active_cells) / cells;
  p.step = steps;
  p.dt_limit = st.dt_limit;
  return opt.progress(p);
}

}  // namespace runout::jobs
