#include "engine/vof/stepping.hpp"

namespace runout::engine::vof {

StepReport VofStepping::step(double t_end) {
  last_ = s_.step(t_end);
  ++steps_;
  StepReport r;
  r.t = last_.t;
  r.dt = last_.dt;
  r.dt_limit = last_.dt_limit;
  r.mass = last_.granular_volume;
  r.max_speed = last_.max_speed;
  r.active_fraction = double(last_.active_cells) / s_.mesh().cells();
  r.kinetic_energy = kinetic_energy();
  return r;
}

double VofStepping::kinetic_energy() const {
  const auto& m = s_.mesh();
  double ke = 0;
  for (int c = 0; c < m.cells(); ++c) {
    const double a = s_.alpha()[std::size_t(c)];
    if (a > 0) ke += 0.5 * a * m.volume[std::size_t(c)] * dot(s_.velocity()[std::size_t(c)], s_.velocity()[std::size_t(c)]);
  }
  return ke;
}

}  // namespace runout::engine::vof
