#pragma once
// Subcommands of the `runout` program. Each returns the process exit code.
#include <string>
#include <vector>

namespace runout::cli {

/// Exit codes (documented in `runout --help`).
enum Exit : int {
  kOk = 0,
  kFailed = 1,
  kUsage = 2,
  kInternal = 3,
  kBadInput = 4,
  kOutput = 5,
  kCancelled = 6,
  kService = 7,    ///< the server cannot be reached or refused the call (token, queue limit, ...)
  kJobFailed = 8,  ///< the job ran and failed
};

int run(const std::vector<std::string>& args);
int verify(const std::vector<std::string>& args);
int version(const std::vector<std::string>& args);
int serve(const std::vector<std::string>& args);
int submit(const std::vector<std::string>& args);
int status(const std::vector<std::string>& args);
int watch(const std::vector<std::string>& args);
int cancel(const std::vector<std::string>& args);
int fetch(const std::vector<std::string>& args);
int health(const std::vector<std::string>& args);
int regress(const std::vector<std::string>& args);
std::string version_report();

}  // namespace runout::cli
