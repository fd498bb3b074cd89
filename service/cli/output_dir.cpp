#include "service/cli/output_dir.hpp"

#include "jobs/formats/run_record.hpp"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace runout::cli {

namespace {

// `inner` is `outer` or lies below it (both absolute, canonical).
bool is_within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

fs::path canonical_or_self(const fs::path& p) {
  std::error_code ec;
  auto c = fs::weakly_canonical(p, ec);
  return ec ? p : c;
}

// runout's run record: run.json, a runout.v1.RunRecord whose software is named "runout".
bool has_run_record(const fs::path& dir) { return jobs::is_run_record((dir / "run.json").string()); }

// What `--force` may replace: a previous result (its run record), the job.log alone of a fetched
// failed job, or an empty directory. `dir` is a directory (not a link).
bool replaceable(const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::directory_entry> entries;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    entries.push_back(*it);
    if (entries.size() > 1) break;
  }
  if (ec) return false;
  if (entries.empty()) return true;
  if (entries.size() == 1 && entries[0].path().filename() == "job.log" && entries[0].is_regular_file(ec) &&
      !entries[0].is_symlink(ec))
    return true;
  return has_run_record(dir);
}

}  // namespace

fs::path output_path(const std::string& out) {
  fs::path p = fs::absolute(out).lexically_normal();
  while (!p.has_filename() && p.has_relative_path()) p = p.parent_path();  // "a/b/" -> "a/b"
  return p;
}

std::string check_output_dir(const fs::path& dest, bool force, const std::string& shown) {
  const std::string named = "output directory '" + shown + "'";
  std::error_code ec;
  const auto st = fs::symlink_status(dest, ec);
  if (st.type() == fs::file_type::not_found) return "";
  if (ec) return "cannot look at " + named + ": " + ec.message();
  if (st.type() == fs::file_type::symlink)
    return named + " is a symbolic link: runout does not replace it, even with --force; give the directory it points to or a new name";
  if (st.type() != fs::file_type::directory)
    return named + " exists and is not a directory: runout does not replace it, even with --force; choose another --out";
  std::error_code ec2;
  const fs::path cwd = canonical_or_self(fs::current_path(ec2));
  if (!ec2 && is_within(cwd, canonical_or_self(dest)))
    return named + " is the current directory or holds it: runout does not replace it, even with --force; give a new"
           " subdirectory, e.g. --out ./results";
  if (!replaceable(dest))
    return named + " exists and is not a previous result of runout (no run.json of runout in it): runout does not replace"
           " it, even with --force; choose another --out";
  if (!force) return named + " exists (use --force to replace it)";
  return "";
}

std::string input_inside(const fs::path& dest, const std::vector<std::string>& inputs) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dest, ec))) return "";
  const fs::path d = canonical_or_self(dest);
  for (const auto& f : inputs)
    if (!f.empty() && is_within(canonical_or_self(fs::absolute(f)), d)) return f;
  return "";
}

StagedOutput::StagedOutput(const fs::path& dest, bool force) : dest_(dest), force_(force) {
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
  // Checked again: DIR may have appeared, or changed, while the run computed.
  const std::string why = check_output_dir(dest_, force_, dest_.string());
  if (!why.empty()) {
    error_ = "results not moved into place: " + why;
    return false;
  }
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dest_, ec))) {
    fs::rename(tmp_, dest_, ec);
    if (ec) {
      error_ = "cannot move the results to '" + dest_.string() + "': " + ec.message();
      return false;
    }
    published_ = true;
    return true;
  }
  // A previous result: moved aside, the new one moved in, then the old one removed.
  std::string name = ".";
  name += dest_.filename().string();
  name += ".old-";
  name += std::to_string(getpid());
  const fs::path aside = dest_.parent_path() / name;
  fs::remove_all(aside, ec);
  ec.clear();
  fs::rename(dest_, aside, ec);
  if (ec) {
    error_ = "cannot move the previous result '" + dest_.string() + "' aside (it is kept): " + ec.message();
    return false;
  }
  fs::rename(tmp_, dest_, ec);
  if (ec) {
    error_ = "cannot move the results to '" + dest_.string() + "': " + ec.message();
    std::error_code back;
    fs::rename(aside, dest_, back);
    error_ += back ? "; the previous result is in '" + aside.string() + "'" : " (the previous result is kept)";
    return false;
  }
  published_ = true;
  fs::remove_all(aside, ec);
  if (ec) note_ = "the previous result moved to '" + aside.string() + "' could not be removed: " + ec.message();
  return true;
}

}  // namespace runout::cli
