#pragma once
// The hazard maps of a 3D run on the scenario's grid: the cells of each grid cell's columns (one, or
// R x R with mesh.refinement R) integrated through the depth after every step. The flow depth normal
// to the ground is the material volume over the grid cell's plan area (the vertical thickness) times
// the cosine of the ground's slope, as the depth-averaged engine measures it; the depth-averaged
// velocity is the material's momentum over its volume; the surface speed the fastest of the columns'
// highest cells at least half full; the ground's normal stress the columns' mean of the ground cell's
// pressure less the column's air above it. The same files as the
// depth-averaged engine come from these maps (jobs/drivers/hazard_outputs.hpp), plus the surface
// speed and the ground stress.
#include <string>
#include <vector>

#include "engine/sh2d.hpp"
#include "engine/vof/backend.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/drivers/vof_terrain/mesh.hpp"

namespace runout::jobs::vof_terrain {


/// The flow through the depth at a point: [height above the ground, alpha, speed] per layer.
struct Profile {
  std::vector<double> height, alpha, speed;
};

struct HazardSettings {
  double rho = 300;              ///< material density [kg/m3] (rho u^2)
  double rho_air = 1;            ///< the air's (the ground stress less the air column)
  double flow_threshold = 0.01;  ///< [m] normal depth that counts as flowing
};

class ColumnHazard {
 public:
  /// A point whose profile through the depth is kept: its grid cell and the column it lies in.
  struct Tracked {
    std::size_t grid_cell = 0, column = 0;
  };
  /// cos_slope: per grid cell, the cosine of the ground's slope (normal depth = vertical x cos).
  ColumnHazard(const Columns& cols, const engine::vof::Mesh& m, std::vector<double> cos_slope, HazardSettings s,
               std::vector<Tracked> tracked = {});

  /// After each step (and at t = 0): the running maxima, arrival times and the tracked columns'
  /// profiles at their deepest.
  void update(double t, const engine::vof::VofBackend& s);
  /// The normal depth per grid cell now.
  std::vector<double> depth(const engine::vof::VofBackend& s) const;
  /// The final depth (the deposit) from the solver's state at the end.
  void finish(const engine::vof::VofBackend& s);

  const engine::HazardMaps& maps() const { return hz_; }
  const std::vector<double>& max_surface_speed() const { return max_surface_; }
  const std::vector<double>& max_ground_stress() const { return max_stress_; }
  /// Tracked column n: when it was deepest and its profile then.
  double deepest_time(std::size_t n) const { return deepest_t_[n]; }
  const Profile& deepest_profile(std::size_t n) const { return deepest_[n]; }

  void save(VofCheckpoint& cp) const;
  /// Throws ScenarioError naming `path` when the checkpoint lacks the maps or they are of another grid.
  void restore(const VofCheckpoint& cp, const std::string& path);
  /// The flow through mesh column `col` now: per layer (those a structure takes left out) its
  /// middle's height above the ground, phase fraction and speed.
  Profile profile(std::size_t col, const engine::vof::VofBackend& s) const;

 private:
  struct Column {
    double depth = 0, speed = 0, surface_speed = 0, ground_stress = 0;
  };
  Column column(std::size_t gc, const engine::vof::VofBackend& s) const;

  const Columns& cols_;
  const engine::vof::Mesh& m_;
  std::vector<double> cos_;
  HazardSettings set_;
  std::vector<Tracked> tracked_;
  engine::HazardMaps hz_;
  std::vector<double> max_surface_, max_stress_;
  std::vector<double> deepest_t_;
  std::vector<Profile> deepest_;
};

}  // namespace runout::jobs::vof_terrain
