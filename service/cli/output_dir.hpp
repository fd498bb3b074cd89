#pragma once
// Output directories of the command line (`runout run`, `runout fetch`): results are written to a
// temporary sibling and moved into place only when complete, so DIR never holds a partial result.
#include <filesystem>
#include <string>

namespace runout::cli {

class StagedOutput {
 public:
  /// Creates `.<name>.tmp-<pid>` beside `dest` (and dest's parent). On failure ok() is false and
  /// error() says why.
  explicit StagedOutput(const std::filesystem::path& dest);
  /// Removes the staging directory unless publish() moved it.
  ~StagedOutput();
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const std::filesystem::path& path() const { return tmp_; }
  /// Replace `dest` by the staged results; false (and error()) when the move fails.
  bool publish();

 private:
  std::filesystem::path dest_, tmp_;
  std::string error_;
  bool published_ = false;
};

}  // namespace runout::cli
