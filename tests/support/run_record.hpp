#pragma once
// Reading run.json in tests: the typed run record (jobs/formats/run_record.hpp), and a figure of it
// by field name for tests that compare many runs' figures alike.
#include <google/protobuf/message.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "jobs/formats/run_record.hpp"

namespace runout::test_support {

inline runout::v1::RunRecord run_record(const std::filesystem::path& path) { return runout::jobs::read_run_record(path.string()); }

/// A number of the record (or of a station) by its field name (jobs::figure_by_name); NaN when the
/// record lacks it.
inline double record_figure(const google::protobuf::Message& rec, const std::string& name) { return runout::jobs::figure_by_name(rec, name); }
inline double record_figure(const std::filesystem::path& run_json, const std::string& name) { return record_figure(run_record(run_json), name); }

/// The station at x (NaN-filled when there is none).
inline runout::v1::Station station_at(const runout::v1::RunRecord& rec, double x) {
  for (const auto& s : rec.stations())
    if (std::abs(s.x_m() - x) < 1e-9) return s;
  runout::v1::Station none;
  none.set_depth_m(NAN);
  none.set_bed_y_m(NAN);
  none.set_depth_averaged_u_m_s(NAN);
  none.set_surface_u_m_s(NAN);
  none.set_basal_speed_m_s(NAN);
  return none;
}

inline std::vector<double> as_vector(const google::protobuf::RepeatedField<double>& v) { return {v.begin(), v.end()}; }

}  // namespace runout::test_support
