#pragma once
// The scenario fields that name input files, in one list: the service's client uploads what they
// name and puts the upload's reference in their place, the server resolves each (an upload, or a file
// inside its data roots) before anything reads it, and an ensemble run locally makes them absolute
// for its members' worker processes. A new input field of the scenario is one more line here.
#include <filesystem>
#include <string>

#include "runout/v1/scenario.pb.h"

namespace runout::jobs {

/// Calls f(field, path) for every input file field that is set ("releases[0].thickness_raster",
/// the path to read or replace).
template <class F>
void for_each_input_path(v1::Scenario& s, F f) {
  auto each = [&](const std::string& field, std::string* path) {
    if (!path->empty()) f(field, path);
  };
  each("dem.path", s.mutable_dem()->mutable_path());
  if (s.has_area_of_interest()) each("area_of_interest.path", s.mutable_area_of_interest()->mutable_path());
  for (int k = 0; k < s.releases_size(); ++k) {
    const std::string at = "releases[" + std::to_string(k) + "]";
    each(at + ".path", s.mutable_releases(k)->mutable_path());
    each(at + ".thickness_raster", s.mutable_releases(k)->mutable_thickness_raster());
  }
  if (s.has_observations()) each("observations.outline_path", s.mutable_observations()->mutable_outline_path());
  if (s.has_path()) each("path.line_path", s.mutable_path()->mutable_line_path());
  if (s.has_mesh()) each("mesh.corridor_path", s.mutable_mesh()->mutable_corridor_path());
  for (int k = 0; k < s.resistance().areas_size(); ++k)
    each("resistance.areas[" + std::to_string(k) + "].path", s.mutable_resistance()->mutable_areas(k)->mutable_path());
  for (int k = 0; k < s.dams_size(); ++k) each("dams[" + std::to_string(k) + "].path", s.mutable_dams(k)->mutable_path());
  for (int k = 0; k < s.structures_size(); ++k) {
    each("structures[" + std::to_string(k) + "].path", s.mutable_structures(k)->mutable_path());
    each("structures[" + std::to_string(k) + "].surface_path", s.mutable_structures(k)->mutable_surface_path());
  }
  if (s.has_nest()) each("nest.path", s.mutable_nest()->mutable_path());
  for (int k = 0; k < s.entrainment().areas_size(); ++k) {
    const std::string at = "entrainment.areas[" + std::to_string(k) + "]";
    each(at + ".path", s.mutable_entrainment()->mutable_areas(k)->mutable_path());
    each(at + ".thickness_raster", s.mutable_entrainment()->mutable_areas(k)->mutable_thickness_raster());
  }
}

/// Every input path of `s` made absolute against `base_dir` (the scenario file's folder).
inline void absolute_inputs(v1::Scenario& s, const std::string& base_dir) {
  for_each_input_path(s, [&](const std::string&, std::string* path) {
    std::filesystem::path p(*path);
    if (p.is_relative()) *path = (std::filesystem::absolute(base_dir) / p).lexically_normal().string();
  });
}

}  // namespace runout::jobs
