#pragma once
// run.json, the run record (runout.v1.RunRecord, service/proto/runout/v1/run_record.proto), written
// and read through protobuf's JSON mapping with the proto's snake_case field names. The JSON form
// (what is printed when, numbers, "NaN") is described in the proto.
#include <stdexcept>
#include <string>
#include <vector>

#include "runout/v1/run_record.pb.h"

namespace runout::jobs {

/// A run record that cannot be read or written; the message names the file.
struct RunRecordError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Write `record` to `path` (replaced): every double rounded to 10 significant digits (the
/// embedded scenario as it is), fields without presence printed even when zero.
void write_run_record(const std::string& path, const v1::RunRecord& record);
/// The same for another record of the same JSON form (an ensemble's runout.v1.EnsembleRecord).
void write_record_json(const std::string& path, const google::protobuf::Message& record);

/// Read a run record. Throws RunRecordError naming `path` when the file is missing or is not a
/// run record (fields it does not know are ignored).
v1::RunRecord read_run_record(const std::string& path);

/// Whether `path` is runout's run record (readable, software.name "runout"); never throws.
bool is_run_record(const std::string& path);

/// One [y, alpha, u] triple of a station's profile.
struct ProfilePoint {
  double y = 0, alpha = 0, u = 0;
};
std::vector<ProfilePoint> station_profile(const v1::Station& s);
/// A profile triple as the record holds it.
google::protobuf::ListValue profile_point(double y, double alpha, double u);

/// A number of a record (or of one of its messages, e.g. a Station) by its field name: the first
/// set field of that name, in field order and depth first (the embedded scenario and lists of
/// messages not searched); NaN when there is none. For readers that compare many figures alike.
double figure_by_name(const google::protobuf::Message& m, const std::string& name);
/// A list of numbers by its field name, found as figure_by_name finds a number (empty if none).
std::vector<double> series_by_name(const google::protobuf::Message& m, const std::string& name);

/// The build of this program: version, git commit, compiler and build type.
v1::Software this_software();

}  // namespace runout::jobs
