#pragma once
// What a laboratory run follows as it goes besides the running figures (jobs/drivers/vof_figures.hpp):
// the benchmark monitors sampled every 10 ms (or 1/50 of the run),
// each a small class that samples the solver and writes its figures into the run record. The
// figures and series so far travel with a checkpoint, so that a continued run's record is the
// uninterrupted run's.
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/vof/backend.hpp"
#include "jobs/drivers/vof_lab/setup.hpp"
#include "jobs/formats/checkpoint.hpp"
#include "jobs/drivers/vof_figures.hpp"
#include "runout/v1/run_record.pb.h"

namespace runout::jobs::vof_lab {

/// The median of a series' finite samples whose times lie in [a, b] (NaN if there is none).
double median_between(const std::vector<double>& t, const std::vector<double>& v, double a, double b);

/// A monitor: one or more series sampled along the run, under names a checkpoint keeps.
class Monitor {
 public:
  virtual ~Monitor() = default;
  virtual void sample(double t, const engine::vof::VofBackend& s) = 0;
  /// Its figures, from its series and their sample times `t`.
  virtual void write(v1::Monitors& rec, const std::vector<double>& t) const = 0;
  /// Its series by checkpoint name (present in every checkpoint, empty where it does not apply).
  virtual std::vector<std::pair<const char*, std::vector<double>*>> series() = 0;
};

/// validation.md B3: the granular outflow through the right end [l/s in the laboratory's 10 cm
/// wide channel; 3D: through the modelled width].
class OutflowMonitor : public Monitor {
 public:
  OutflowMonitor(const LabSetup& su, double end_time);
  void sample(double t, const engine::vof::VofBackend& s) override;
  void write(v1::Monitors& rec, const std::vector<double>& t) const override;
  std::vector<std::pair<const char*, std::vector<double>*>> series() override { return {{"outflow", &q}}; }
  std::vector<double> q;

 private:
  std::vector<int> faces_;
  double per_width_, end_time_;
};

/// validation.md B3: the flux through the gate (the internal faces on x = 0) and the strain rate
/// du/dy there (the least-squares slope of u over the material cells of the column just downstream).
class GateMonitor : public Monitor {
 public:
  GateMonitor(const LabSetup& su, const v1::Lab& L);
  void sample(double t, const engine::vof::VofBackend& s) override;
  void write(v1::Monitors& rec, const std::vector<double>& t) const override;
  std::vector<std::pair<const char*, std::vector<double>*>> series() override { return {{"gate_flux", &flux}, {"gate_strain_rate", &strain}}; }
  bool has_gate() const { return !faces_.empty(); }
  std::vector<double> flux, strain;

 private:
  const LabSetup& su_;
  std::vector<int> faces_;
  int column_;
  double per_width_, end_time_;
};

/// The share of the material (alpha > 0.5) moving faster than 1 cm/s, and when it first reached 99 %.
class MovingShareMonitor : public Monitor {
 public:
  void sample(double t, const engine::vof::VofBackend& s) override;
  void write(v1::Monitors& rec, const std::vector<double>& t) const override;
  std::vector<std::pair<const char*, std::vector<double>*>> series() override { return {{"moving_share", &share}}; }
  std::vector<double> share;
  double t_fluid = -1;
};

/// validation.md B6 (inflow and a wall at the right end): the bore, i.e. the upstream edge of the
/// columns, from the end wall upstream, that hold at least two cells' depth of material and whose
/// depth-averaged speed is below half the inflow's mean speed (at least 5 cm/s). (Not the edge of
/// the resting deposit: under sand's bore the deposit keeps creeping for a while, and that edge
/// stalls and jumps while the bore runs at a constant speed.)
class ShockMonitor : public Monitor {
 public:
  ShockMonitor(const LabSetup& su, const v1::Lab& L);
  bool enabled() const { return end_wall_; }
  void sample(double t, const engine::vof::VofBackend& s) override;
  void write(v1::Monitors& rec, const std::vector<double>& t) const override;
  std::vector<std::pair<const char*, std::vector<double>*>> series() override { return {{"shock", &x}}; }
  std::vector<double> x;

 private:
  const LabSetup& su_;
  bool end_wall_;
  double inflow_speed_ = 0, x_max_, length_;
};

/// validation.md B1, the rotating box: the free surface's angle to the horizontal (perpendicular to
/// gravity) in the central region (within 5 cm of the box centre), from the principal axis of the
/// points where alpha crosses 0.5 between neighbouring cells.
class SurfaceAngleMonitor : public Monitor {
 public:
  SurfaceAngleMonitor(const LabSetup& su, const v1::Lab& L, double every);
  bool enabled() const { return rotating_; }
  void sample(double t, const engine::vof::VofBackend& s) override;
  void write(v1::Monitors& rec, const std::vector<double>& t) const override;
  std::vector<std::pair<const char*, std::vector<double>*>> series() override {
    return {{"surface_angle", &angle}, {"flowing_layer", &layer}};
  }
  std::vector<double> angle, layer;

 private:
  double flowing_layer(const engine::vof::VofBackend& s, double mx, double my, double dir) const;
  const LabSetup& su_;
  bool rotating_;
  engine::vof::Vec centre_;
  double period_, every_;
};

/// The obstacles' load (engine/vof/loads.hpp): the pressure's force on the "obstacle" patch and the
/// highest face pressure, per sample.
class ObstacleLoadMonitor : public Monitor {
 public:
  explicit ObstacleLoadMonitor(const LabSetup& su, double end_time);
  bool enabled() const { return enabled_; }
  void sample(double t, const engine::vof::VofBackend& s) override;
  void write(v1::Monitors& rec, const std::vector<double>& t) const override;
  std::vector<std::pair<const char*, std::vector<double>*>> series() override {
    return {{"obstacle_fx", &fx}, {"obstacle_fy", &fy}, {"obstacle_fz", &fz}, {"obstacle_pmax", &pmax}};
  }
  std::vector<double> fx, fy, fz, pmax;

 private:
  bool enabled_ = false;
  double area_ = 0, end_time_;
};

/// The monitors of a run and their sample times.
class LabMonitors {
 public:
  LabMonitors(const LabSetup& su, const v1::Lab& L, double t_start);
  /// Sample when the next sample is due.
  void after_step(double t, const engine::vof::VofBackend& s);
  void save(VofCheckpoint& cp);
  /// Throws ScenarioError naming `path` when the checkpoint lacks a series or the monitor times.
  void restore(const VofCheckpoint& cp, const std::string& path);
  void write(v1::RunRecord& rec) const;

  std::vector<double> t;
  OutflowMonitor outflow;
  GateMonitor gate;
  MovingShareMonitor moving;
  ShockMonitor shock;
  SurfaceAngleMonitor surface;
  ObstacleLoadMonitor obstacle;

 private:
  std::vector<Monitor*> all();
  double every_, next_;
};

}  // namespace runout::jobs::vof_lab
