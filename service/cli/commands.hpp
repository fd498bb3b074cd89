#pragma once
// Subcommands of the `runout` program. Each returns the process exit code.
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}
namespace runout::service {
struct ClientOptions;
}

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
int compare(const std::vector<std::string>& args);
int report(const std::vector<std::string>& args);
std::string version_report();

// The command line of every command is parsed with CLI11 (CLI/CLI.hpp), one CLI::App per command,
// named "runout <command>" (main.cpp).

/// Settings every command's parser shares; call before adding options.
void prepare(CLI::App& app);
/// Parses `args` (the words after the command's name). Returns -1 when the command goes on, else
/// its exit code: kOk after --help (the options on standard output), kUsage after a bad command
/// line ("runout <command>: <message>" on standard error).
int parse_args(CLI::App& app, const std::vector<std::string>& args);
/// Prints "<name>: <message>" on standard error; returns kUsage.
int usage_error(const std::string& name, const std::string& message);
/// A positive integer written as the whole of `v` (--threads, --workers, ...); nothing otherwise.
std::optional<int> positive_int(const std::string& v);

/// The connection options of the client commands (--server, --token, --token-file, --tls-ca,
/// --tls). `server_env`: --server defaults to $RUNOUT_SERVER; --token always to $RUNOUT_TOKEN.
struct Connection {
  std::string token_file;
};
void add_connection_options(CLI::App& app, service::ClientOptions& opt, Connection& c, bool server_env);
/// After parsing: reads --token-file. Returns -1 or, after a message, kUsage.
int finish_connection_options(const CLI::App& app, service::ClientOptions& opt, const Connection& c);

}  // namespace runout::cli
