// The depth-averaged 2D solver's cells by kind and its flux gauges: which cells lie outside the
// domain or next to it, the dams' heights and which cells take the general loops (next to the
// outside, either side of a dam's step, a gauge's cell), and the flux gauges' bookkeeping.
#include <algorithm>

#include "engine/sh2d/solver.hpp"

namespace runout::engine::sh2d_detail {

// The cells outside the domain and next to it, the dams' heights, and the cells that take the general
// loops (general()): next to the outside, on either side of a dam's step, a flux gauge's cell.
void Solver::mark_cells() {
  if (std::any_of(t_.outside.begin(), t_.outside.end(), [](std::uint8_t o) { return o != 0; })) {
    out_ = t_.outside;
    near_out_.assign(n_, 0);
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i)
        near_out_[idx(i, j)] = outside(i, j) || (i > 0 && outside(i - 1, j)) || (i < nx_ - 1 && outside(i + 1, j)) ||
                               (j > 0 && outside(i, j - 1)) || (j < ny_ - 1 && outside(i, j + 1));
  }
  if (std::any_of(cfg_.dam_height.begin(), cfg_.dam_height.end(), [](double d) { return d > 0; })) dam_ = cfg_.dam_height;
  if (near_out_.empty() && dam_.empty() && cfg_.gauges.empty()) return;
  general_.assign(n_, 0);
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const std::size_t k = idx(i, j);
      const bool step = (i > 0 && step_face(k, k - 1)) || (i < nx_ - 1 && step_face(k, k + 1)) ||
                        (j > 0 && step_face(k, k - nx_)) || (j < ny_ - 1 && step_face(k, k + nx_));
      general_[k] = near_outside(k) || step;
    }
  for (const auto& g : cfg_.gauges)
    for (std::size_t k : g.cells) general_[k] = 1;
}

// The flux gauges' counts and each gauge cell's slot (its gauge, its faces' sides, its step's counts).
void Solver::set_gauges() {
  gauge_right_.assign(cfg_.gauges.size(), 0.0);
  gauge_left_.assign(cfg_.gauges.size(), 0.0);
  if (!cfg_.gauges.empty()) gauge_slot_.assign(n_, -1);
  for (std::size_t a = 0; a < cfg_.gauges.size(); ++a)
    for (std::size_t q = 0; q < cfg_.gauges[a].cells.size(); ++q) {
      gauge_slot_[cfg_.gauges[a].cells[q]] = int(slot_gauge_.size());
      slot_gauge_.push_back(int(a));
      slot_sides_.push_back(cfg_.gauges[a].sides[q]);
    }
  slot_right_.assign(slot_gauge_.size(), 0.0);
  slot_left_.assign(slot_gauge_.size(), 0.0);
}

// After a step: what the gauges' cells sent right and left, summed per gauge in the slots' fixed
// order (the same bits on any thread count), the slots cleared for the next step.
void Solver::measure_gauges() {
  for (std::size_t q = 0; q < slot_gauge_.size(); ++q) {
    gauge_right_[slot_gauge_[q]] += slot_right_[q];
    gauge_left_[slot_gauge_[q]] += slot_left_[q];
    slot_right_[q] = slot_left_[q] = 0.0;
  }
}

}  // namespace runout::engine::sh2d_detail
