#include "service/cli/output_dir.hpp"

#include <unistd.h>

namespace fs = std::filesystem;

namespace runout::cli {

StagedOutput::StagedOutput(const fs::path& dest) : dest_(dest) {
  std::error_code ec;
  fs::create_directories(dest.parent_path(), ec);
  std::string name = ".";  // (built step by step: GCC 12 warns falsely on "." + string)
  name += dest.filename().string();
  name += ".tmp-";
  name += std::to_string(getpid());
  tmp_ = dest.parent_path() / name;
  fs::remove_all(tmp_, ec);
  if (!fs::create_directory(tmp_, ec)) error_ = "cannot create '" + tmp_.string() + "': " + ec.message();
}

StagedOutput::~StagedOutput() {
  std::error_code ec;
  if (!published_) fs::remove_all(tmp_, ec);
}

bool StagedOutput::publish() {
  std::error_code ec;
  if (fs::exists(dest_)) fs::remove_all(dest_, ec);
  fs::rename(tmp_, dest_, ec);
  if (ec) {
    error_ = "cannot move the results to '" + dest_.string() + "': " + ec.message();
    return false;
  }
  published_ = true;
  return true;
}

}  // namespace runout::cli
