#include "jobs/drivers/vof_figures.hpp"

#include <algorithm>
#include <cmath>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs {

namespace vof = engine::vof;


void RunningFigures::step(const vof::StepStats& st) {
  ++steps;
  p_its += st.pressure_iterations;
  active_sum += st.active_cells;
  active_max = std::max(active_max, st.active_cells);
  pressure_s += st.seconds_pressure;
  pressure_solve_s += st.seconds_pressure_solve;
  alpha_min = std::min(alpha_min, st.alpha_min);
  alpha_max = std::max(alpha_max, st.alpha_max);
  div = std::max(div, st.divergence);
  last_speed = st.max_speed;
  if (st.max_speed > peak) {
    peak = st.max_speed;
    t_peak = st.t;
  }
  if (st.max_speed >= 0.01) t_rest = -1;
  else if (t_rest < 0 && peak >= 0.01) t_rest = st.t;
}

void RunningFigures::save(VofCheckpoint& cp) const {
  cp.steps = steps;
  cp.figures = {{"peak", peak},
                {"t_peak", t_peak},
                {"t_rest", t_rest},
                {"pressure_s", pressure_s},
                {"pressure_solve_s", pressure_solve_s},
                {"alpha_min", alpha_min},
                {"alpha_max", alpha_max},
                {"div", div},
                {"last_speed", last_speed},
                {"p_its", double(p_its)},
                {"active_sum", active_sum},
                {"active_max", double(active_max)}};
}

void RunningFigures::restore(const VofCheckpoint& cp, const std::string& path) {
  auto f = [&](const char* k) {
    const auto it = cp.figures.find(k);
    if (it == cp.figures.end()) throw ScenarioError("checkpoint " + path + ": damaged (no figure '" + k + "')");
    return it->second;
  };
  peak = f("peak"), t_peak = f("t_peak"), t_rest = f("t_rest"), pressure_s = f("pressure_s"), alpha_min = f("alpha_min");
  alpha_max = f("alpha_max"), div = f("div"), last_speed = f("last_speed"), p_its = long(f("p_its")), active_sum = f("active_sum");
  active_max = int(f("active_max"));
  // A timing only, and absent from checkpoints written before it was carried.
  const auto ps = cp.figures.find("pressure_solve_s");
  pressure_solve_s = ps == cp.figures.end() ? 0.0 : ps->second;
  steps = cp.steps;
}

void RunningFigures::write(v1::RunRecord& rec) const {
  auto* so = rec.mutable_solver();
  so->set_steps(int(steps));
  so->set_pressure_iterations(double(p_its));
  so->set_alpha_min(alpha_min);
  so->set_alpha_max(alpha_max);
  so->set_max_divergence_1_s(div);
  so->set_active_cells_mean(steps ? active_sum / steps : NAN);
  so->set_active_cells_max(active_max);
  auto* re = rec.mutable_results();
  re->set_peak_speed_m_s(peak);
  re->set_peak_speed_time_s(t_peak);
  re->set_rest_time_s(t_rest >= 0 ? t_rest : NAN);
  re->set_final_speed_m_s(last_speed);
  rec.mutable_timings_s()->set_pressure(pressure_s);
  rec.mutable_timings_s()->set_pressure_solve(pressure_solve_s);
}

}  // namespace runout::jobs
