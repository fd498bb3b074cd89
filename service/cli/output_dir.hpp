#pragma once
// Output directories of the command line (`runout run`, `runout fetch`): results are written to a
// temporary sibling and moved into place only when complete, so DIR never holds a partial result.
//
// What may be written (docs/user/outputs.md "Outputs of `runout run`"): a DIR that does not exist; with --force
// also a previous result, i.e. a directory whose run.json is runout's run record ("software" named
// "runout"), a directory holding nothing but the job.log of a fetched failed job, or an empty
// directory. Anything else is refused, even with --force: a regular file, a symbolic link, a
// directory of other files, and the current directory or one that holds it. A previous result is
// replaced only once the new one is complete: it is moved aside, the new one moved in, then the old
// one removed; if a step fails the previous result stays (or is put back).
#include <filesystem>
#include <string>
#include <vector>

namespace runout::cli {

/// The absolute, normalised form of `--out DIR` (no trailing '/', '.' or '..').
std::filesystem::path output_path(const std::string& out);

/// Whether `dest` (an output_path) may be written: "" when it may, else the reason, naming `shown`
/// (the directory as the user gave it).
std::string check_output_dir(const std::filesystem::path& dest, bool force, const std::string& shown);

/// When `dest` exists and would be replaced: the first of `inputs` (files the run reads or writes
/// besides its results) that lies inside it, so that replacing it would delete that file; "" if none.
std::string input_inside(const std::filesystem::path& dest, const std::vector<std::string>& inputs);

class StagedOutput {
 public:
  /// Creates `.<name>.tmp-<pid>` beside `dest` (an output_path; and dest's parent). On failure ok() is
  /// false and error() says why.
  explicit StagedOutput(const std::filesystem::path& dest, bool force = false);
  /// Removes the staging directory unless publish() moved it.
  ~StagedOutput();
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  /// After a successful publish(): a problem that did not stop it (the previous result could not be
  /// removed completely), else empty.
  const std::string& note() const { return note_; }
  const std::filesystem::path& path() const { return tmp_; }
  /// Move the staged results to `dest`, replacing a previous result there (checked again now); false
  /// (and error()) when that is not allowed or a move fails, with any previous result left in place.
  bool publish();

 private:
  std::filesystem::path dest_, tmp_;
  bool force_ = false;
  std::string error_, note_;
  bool published_ = false;
};

}  // namespace runout::cli
