#include "jobs/drivers/nest/boundary.hpp"

#include <algorithm>
#include <cmath>

#include "jobs/scenario/scenario.hpp"

namespace runout::jobs::nest {

NestBoundary::NestBoundary(const terrain::Grid& g, std::vector<std::uint8_t> cells, const std::string& what) : g_(g), cells_(std::move(cells)) {
  const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const std::size_t k = std::size_t(j) * g.nx + i;
      if (!cells_[k]) continue;
      if (!g.outside.empty() && g.outside[k]) throw ScenarioError(what + ": the nest reaches outside the domain at grid cell (" + std::to_string(i) + ", " + std::to_string(j) + ")");
      if (i == 0 || j == 0 || i == g.nx - 1 || j == g.ny - 1)
        throw ScenarioError(what + ": the nest reaches the grid's edge at grid cell (" + std::to_string(i) + ", " + std::to_string(j) +
                            "); keep it at least one cell inside");
      int n = 0;
      for (int s = 0; s < 4; ++s) {
        const std::size_t m = std::size_t(j + dj[s]) * g.nx + std::size_t(i + di[s]);
        if (cells_[m]) continue;
        faces_.push_back({k, m, s});
        ++n;
      }
      if (n > 2)
        throw ScenarioError(what + ": the nest is one cell wide at grid cell (" + std::to_string(i) + ", " + std::to_string(j) +
                            "); make it at least two cells wide everywhere");
    }
  if (cell_count() == 0) throw ScenarioError(what + ": the nest covers no cell of the grid");
}

int NestBoundary::cell_count() const {
  return int(std::count_if(cells_.begin(), cells_.end(), [](std::uint8_t c) { return c != 0; }));
}

std::vector<engine::FluxGauge> NestBoundary::gauges(std::size_t first) {
  first_ = first;
  std::vector<engine::FluxGauge> out;
  right_.assign(faces_.size(), -1);
  left_.assign(faces_.size(), -1);
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    if (!out.empty() && out.back().cells.back() == faces_[f].inside) {  // the cell's second boundary face: to the left
      out.back().sides.back()[std::size_t(faces_[f].side)] = -1;
      left_[f] = int(out.size()) - 1;
      continue;
    }
    engine::FluxGauge gauge{"nest boundary " + std::to_string(out.size()), {faces_[f].inside}, {{0, 0, 0, 0}}};
    gauge.sides.back()[std::size_t(faces_[f].side)] = 1;
    right_[f] = int(out.size());
    out.push_back(std::move(gauge));
  }
  last_right_.assign(out.size(), 0.0);
  last_left_.assign(out.size(), 0.0);
  return out;
}

void NestBoundary::record(double t, const engine::Sh2dEngine& e) {
  const auto& R = e.gauge_right();
  const auto& L = e.gauge_left();
  const auto st = e.state();
  times_.push_back(t);
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    double sent = 0;  // what the inside cell sent out through the face in the step
    if (right_[f] >= 0) sent = R[first_ + std::size_t(right_[f])] - last_right_[std::size_t(right_[f])];
    else sent = L[first_ + std::size_t(left_[f])] - last_left_[std::size_t(left_[f])];
    const std::size_t o = faces_[f].outside;
    const double H = st.H[o];
    entered_.push_back(-sent);
    depth_.push_back(H);
    east_.push_back(H > 1e-6 ? st.HU[o] / H : 0.0);
    north_.push_back(H > 1e-6 ? st.HV[o] / H : 0.0);
    max_depth_ = std::max(max_depth_, H);
    max_speed_ = std::max(max_speed_, std::hypot(east_.back(), north_.back()));
  }
  for (std::size_t q = 0; q < last_right_.size(); ++q) {
    last_right_[q] = R[first_ + q];
    last_left_[q] = L[first_ + q];
  }
}

double NestBoundary::first_inflow_time() const {
  const std::size_t n = faces_.size();
  for (std::size_t s = 0; s + 1 < times_.size(); ++s)
    for (std::size_t k = 0; k < n; ++k)
      if (entered_[s * n + k] > 0) return times_[s];
  return times_.back();
}

double NestBoundary::inflow_volume() const {
  double v = 0;
  for (double x : entered_) v += std::max(x, 0.0);
  return v;
}

bool NestBoundary::inflow(std::size_t k, double t0, double t1, FaceInflow& out) const {
  const std::size_t n = faces_.size();
  if (times_.size() < 2 || t0 >= times_.back()) return false;
  // Step s covers (times_[s], times_[s + 1]]; its row in the record is s.
  auto step_of = [&](double t) {
    const auto it = std::upper_bound(times_.begin(), times_.end(), t);
    return std::size_t(std::clamp<long>(long(it - times_.begin()) - 1, 0, long(times_.size()) - 2));
  };
  double vol = 0;
  const std::size_t s0 = step_of(t0);
  if (t1 > t0) {
    for (std::size_t s = s0; s + 1 < times_.size() && times_[s] < t1; ++s) {
      const double a = std::max(t0, times_[s]), b = std::min(t1, times_[s + 1]);
      if (b > a) vol += std::max(entered_[s * n + k], 0.0) * (b - a) / (times_[s + 1] - times_[s]);
    }
    out.q = vol / (t1 - t0);
  } else {
    out.q = std::max(entered_[s0 * n + k], 0.0) / (times_[s0 + 1] - times_[s0]);
  }
  if (!(out.q > 0)) return false;
  const std::size_t s = step_of(0.5 * (t0 + t1));
  out.depth = std::max(depth_[s * n + k], s > 0 ? depth_[(s - 1) * n + k] : 0.0);
  out.east = east_[s * n + k];
  out.north = north_[s * n + k];
  return true;
}

}  // namespace runout::jobs::nest
