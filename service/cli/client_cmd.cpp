// Client commands: submit, status, watch, cancel, fetch, health. Each talks to a server given by
// --server HOST:PORT (or RUNOUT_SERVER) with the bearer token of --token / --token-file (or
// RUNOUT_TOKEN).
#include <CLI/CLI.hpp>
#include <grpcpp/grpcpp.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "jobs/scenario/scenario.hpp"
#include "service/cli/commands.hpp"
#include "service/cli/run_ensemble.hpp"
#include "jobs/system/store.hpp"
#include "service/cli/output_dir.hpp"
#include "service/client/client.hpp"

namespace fs = std::filesystem;

namespace runout::cli {

namespace {

// The exit code of a failed call.
int code_of(const service::RpcError& e) {
  switch (grpc::StatusCode(e.code)) {
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::NOT_FOUND:
    case grpc::StatusCode::FAILED_PRECONDITION: return kBadInput;
    case grpc::StatusCode::CANCELLED: return kCancelled;
    default: return kService;
  }
}

int code_of_state(v1::JobState s) {
  switch (s) {
    case v1::SUCCEEDED: return kOk;
    case v1::CANCELLED: return kCancelled;
    case v1::FAILED: return kJobFailed;
    default: return kOk;
  }
}

std::string progress_line(const v1::Job& j) {
  const auto& p = j.progress();
  char b[256];
  if (j.members().total() > 0 && !jobs::is_final(j.state()))
    return j.id() + " ensemble " + (j.state() == v1::RUNNING ? "aggregating: " : "") + ensemble_progress(j.members(), isatty(fileno(stderr)));
  if (j.state() == v1::RUNNING && p.steps() > 0)
    std::snprintf(b, sizeof b, "%s running: t = %.1f / %.0f s, dt = %.4f s, volume = %.4g m3, max speed = %.1f m/s, active = %.1f %%, left <= %.0f s",
                  j.id().c_str(), p.simulated_s(), p.end_time_s(), p.dt_s(), p.volume_m3(), p.max_speed_m_s(),
                  100 * p.active_fraction(), p.seconds_left());
  else
    std::snprintf(b, sizeof b, "%s %s", j.id().c_str(), service::state_word(j.state()).c_str());
  return b;
}

// Follow a job, printing a progress line to standard error; returns the final job.
v1::Job follow(service::Client& c, const std::string& id, bool quiet) {
  const bool tty = isatty(fileno(stderr));
  v1::JobState last = v1::JOB_STATE_UNSPECIFIED;
  auto printed = std::chrono::steady_clock::now() - std::chrono::hours(1);
  auto j = c.watch(id, [&](const v1::Job& ev) {
    if (quiet) return;
    const bool changed = ev.state() != last;
    last = ev.state();
    const auto now = std::chrono::steady_clock::now();
    if (tty) {
      std::fprintf(stderr, "\r%-150s", progress_line(ev).c_str());
    } else if (changed || now - printed > std::chrono::seconds(5)) {  // a log, not an animation
      std::fprintf(stderr, "%s\n", progress_line(ev).c_str());
      printed = now;
    }
    std::fflush(stderr);
  });
  if (!quiet && tty) std::fprintf(stderr, "\n");
  return j;
}

void print_job(const v1::Job& j) {
  std::printf("job        %s\n", j.id().c_str());
  std::printf("name       %s\n", j.name().c_str());
  std::printf("state      %s\n", service::state_word(j.state()).c_str());
  std::printf("scenario   %s\n", j.scenario_hash().c_str());
  std::printf("created    %s\nupdated    %s\nattempts   %d\n", j.created_utc().c_str(), j.updated_utc().c_str(), j.attempts());
  if (j.members().total() > 0) std::printf("members    %s\n", ensemble_progress(j.members(), false).c_str());
  else if (j.state() == v1::RUNNING) std::printf("progress   %s\n", progress_line(j).c_str());
  if (!j.error().empty()) std::printf("error      %s\n", j.error().c_str());
  if (j.result_bytes() > 0) std::printf("results    %.1f MiB\n", double(j.result_bytes()) / (1 << 20));
  std::printf("history\n");
  for (const auto& t : j.transitions())
    std::printf("  %s  %-9s  %s\n", t.time_utc().c_str(), service::state_word(t.state()).c_str(), t.reason().c_str());
}

}  // namespace

void add_connection_options(CLI::App& app, service::ClientOptions& opt, Connection& c, bool server_env) {
  auto* server = app.add_option("--server", opt.server,
                                server_env ? "The server (default $RUNOUT_SERVER, else 127.0.0.1:50051)"
                                           : "A running server to use instead of an embedded one")
                     ->type_name("HOST:PORT");
  if (server_env) server->envname("RUNOUT_SERVER");
  app.add_option("--token", opt.token, "Bearer token (default $RUNOUT_TOKEN)")->type_name("TOKEN")->envname("RUNOUT_TOKEN");
  app.add_option("--token-file", c.token_file, "Read the bearer token from the first line of FILE")->type_name("FILE");
  app.add_option("--tls-ca", opt.tls_ca, "TLS, with the PEM certificate (FILE) of the certificate authority that signed the server's certificate")
      ->type_name("FILE");
  app.add_flag("--tls", opt.tls, "TLS, with the system's root certificates");
}

int finish_connection_options(const CLI::App& app, service::ClientOptions& opt, const Connection& c) {
  if (!app.count("--token-file")) return -1;
  std::ifstream in(c.token_file);
  std::string t;
  if (!in || !std::getline(in, t))
    return usage_error(app.get_name(), "--token-file '" + c.token_file + "': cannot read a token from it");
  while (!t.empty() && (t.back() == '\r' || t.back() == ' ' || t.back() == '\t')) t.pop_back();
  opt.token = t;
  return -1;
}

namespace {

// A client command's parser: its description and the connection options.
struct ClientApp {
  CLI::App app;
  service::ClientOptions opt;
  Connection conn;
  ClientApp(const std::string& description, const std::string& name) : app(description, name) {
    prepare(app);
    add_connection_options(app, opt, conn, true);
  }
  int parse(const std::vector<std::string>& args) {
    if (const int rc = parse_args(app, args); rc >= 0) return rc;
    return finish_connection_options(app, opt, conn);
  }
};

}  // namespace

int submit(const std::vector<std::string>& args) {
  ClientApp c("Upload the scenario's input files and queue it; prints the job id and state.", "runout submit");
  std::string file, request_id, ranks;
  bool wait = false, server_paths = false, quiet = false;
  c.app.add_option("SCENARIO.json", file, "The scenario file (required)");
  c.app.add_option("--ranks", ranks, "Run the job's 3D run over N MPI ranks (the scenario's `ranks`; docs/design/parallel.md)")
      ->type_name("N");
  c.app.add_flag("--wait", wait, "Follow the job to its end (progress on standard error); exit as watch does");
  c.app.add_flag("--quiet", quiet, "With --wait: no progress lines");
  c.app.add_option("--request-id", request_id, "Idempotency key: a repeated submission with it answers the same job")
      ->type_name("ID");
  c.app.add_flag("--server-paths", server_paths,
                 "Send the input paths as they are, for files inside the server's data roots (no upload)");
  if (const int rc = c.parse(args); rc >= 0) return rc;
  if (file.empty())
    return usage_error("runout submit", "usage: runout submit SCENARIO.json [--wait] [--quiet] [--request-id ID] "
                                        "[--server-paths] [--ranks N] (see runout submit --help)");
  const auto n_ranks = positive_int(ranks);
  if (c.app.count("--ranks") && !n_ranks) return usage_error("runout submit", "--ranks takes a positive integer, got '" + ranks + "'");
  v1::Scenario s;
  try {
    std::ifstream in(file);
    if (!in) throw jobs::ScenarioError("cannot read scenario '" + file + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    s = jobs::parse_scenario_json(ss.str());
    if (n_ranks) s.set_ranks(*n_ranks);
  } catch (const jobs::ScenarioError& e) {
    std::cerr << "runout submit: " << e.what() << "\n";
    return kBadInput;
  }
  try {
    service::Client client(c.opt);
    // Inputs: uploaded from here (content-addressed, so a repeated upload is free), or, with
    // --server-paths, named by path inside the server's data roots.
    if (!server_paths) s = service::upload_inputs(client, s, fs::absolute(file).parent_path().string());
    const auto j = client.submit(s, request_id);
    if (!wait) {
      std::printf("%s %s\n", j.id().c_str(), service::state_word(j.state()).c_str());
      return kOk;
    }
    const auto fin = follow(client, j.id(), quiet);
    std::printf("%s %s\n", fin.id().c_str(), service::state_word(fin.state()).c_str());
    if (!fin.error().empty()) std::cerr << "runout submit: job " << fin.id() << " failed: " << fin.error() << "\n";
    return code_of_state(fin.state());
  } catch (const service::RpcError& e) {
    std::cerr << "runout submit: " << e.what() << "\n";
    return code_of(e);
  }
}

int status(const std::vector<std::string>& args) {
  ClientApp c("One job in detail (state history, error), or the list of this client's jobs and their disk use.",
              "runout status");
  std::vector<v1::JobState> states;
  std::vector<std::string> words;
  std::string id;
  c.app.add_option("JOB", id, "The job (default: list the jobs)");
  c.app.add_option("--state", words, "List only jobs in this state: queued, running, succeeded, failed, cancelled (repeat for more)")
      ->type_name("STATE")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  if (const int rc = c.parse(args); rc >= 0) return rc;
  for (const auto& v : words) {
    v1::JobState s = v1::JOB_STATE_UNSPECIFIED;
    for (auto t : {v1::QUEUED, v1::RUNNING, v1::SUCCEEDED, v1::FAILED, v1::CANCELLED})
      if (service::state_word(t) == v) s = t;
    if (s == v1::JOB_STATE_UNSPECIFIED)
      return usage_error("runout status", "unknown state '" + v + "' (valid: queued, running, succeeded, failed, cancelled)");
    states.push_back(s);
  }
  try {
    service::Client client(c.opt);
    if (!id.empty()) {
      print_job(client.get(id));
      return kOk;
    }
    std::string token;
    std::int64_t bytes = 0;
    int n = 0;
    bool header = false;
    do {
      const auto r = client.list(states, 200, token);
      if (!header) std::printf("%-18s %-10s %-24s %s\n", "job", "state", "updated", "name");
      header = true;
      for (const auto& j : r.jobs()) {
        std::printf("%-18s %-10s %-24s %s\n", j.id().c_str(), service::state_word(j.state()).c_str(), j.updated_utc().c_str(),
                    j.name().c_str());
        ++n;
      }
      token = r.next_page_token();
      bytes = r.result_bytes_total();
    } while (!token.empty());
    std::printf("%d job(s); results on the server: %.1f MiB\n", n, double(bytes) / (1 << 20));
    return kOk;
  } catch (const service::RpcError& e) {
    std::cerr << "runout status: " << e.what() << "\n";
    return code_of(e);
  }
}

int watch(const std::vector<std::string>& args) {
  ClientApp c("Follow a job's progress until it ends (exit 0 succeeded, 6 cancelled, 8 failed).", "runout watch");
  std::string id;
  c.app.add_option("JOB", id, "The job (required)");
  if (const int rc = c.parse(args); rc >= 0) return rc;
  if (id.empty()) return usage_error("runout watch", "usage: runout watch JOB (see runout watch --help)");
  try {
    service::Client client(c.opt);
    const auto j = follow(client, id, false);
    std::printf("%s %s\n", j.id().c_str(), service::state_word(j.state()).c_str());
    if (!j.error().empty()) std::cerr << "runout watch: job " << j.id() << " failed: " << j.error() << "\n";
    return code_of_state(j.state());
  } catch (const service::RpcError& e) {
    std::cerr << "runout watch: " << e.what() << "\n";
    return code_of(e);
  }
}

int cancel(const std::vector<std::string>& args) {
  ClientApp c("Cancel a queued or running job.", "runout cancel");
  std::string id;
  c.app.add_option("JOB", id, "The job (required)");
  if (const int rc = c.parse(args); rc >= 0) return rc;
  if (id.empty()) return usage_error("runout cancel", "usage: runout cancel JOB (see runout cancel --help)");
  try {
    service::Client client(c.opt);
    const auto j = client.cancel(id);
    std::printf("%s %s%s\n", j.id().c_str(), service::state_word(j.state()).c_str(),
                j.state() == v1::RUNNING ? " (cancel requested; it stops at its next progress point)" : "");
    return kOk;
  } catch (const service::RpcError& e) {
    std::cerr << "runout cancel: " << e.what() << "\n";
    return code_of(e);
  }
}

int fetch(const std::vector<std::string>& args) {
  ClientApp c("Download a job's results (checksums verified) into DIR; for a failed job, its log.", "runout fetch");
  std::string id, out;
  bool force = false;
  c.app.add_option("JOB", id, "The job (required)");
  c.app.add_option("--out", out,
                   "Result directory (required); as for runout run, it must not exist, or hold a previous result or a "
                   "previous fetch of a failed job (job.log alone) to be replaced with --force")
      ->type_name("DIR");
  c.app.add_flag("--force", force, "Replace DIR when it holds a previous result or fetch (see --out)");
  bool with_members = false;
  c.app.add_flag("--members", with_members, "An ensemble: also each member's results, into DIR/members/member_<k>");
  if (const int rc = c.parse(args); rc >= 0) return rc;
  if (id.empty() || out.empty())
    return usage_error("runout fetch", "usage: runout fetch JOB --out DIR [--force] [--members] (see runout fetch --help)");
  // DIR: absent, or with --force a previous result or fetch (output_dir.hpp); never anything else.
  const fs::path dest = output_path(out);
  if (const auto why = check_output_dir(dest, force, out); !why.empty()) {
    std::cerr << "runout fetch: " << why << "\n";
    return kOutput;
  }
  StagedOutput staged(dest, force);
  if (!staged.ok()) {
    std::cerr << "runout fetch: " << staged.error() << "\n";
    return kOutput;
  }
  const fs::path tmp = staged.path();
  try {
    service::Client client(c.opt);
    const auto j = client.get(id);
    const auto files = client.results(id);
    if (j.state() != v1::SUCCEEDED) {
      std::cerr << "runout fetch: job " << id << " is " << service::state_word(j.state())
                << (j.error().empty() ? "" : " (" + j.error() + ")") << "; fetching its log only\n";
    }
    std::int64_t bytes = 0;
    int count = 0;
    auto download_all = [&](const std::string& job, const v1::ListResultsResponse& list, const fs::path& into) {
      for (const auto& f : list.files()) {
        if (!service::result_name_ok(f.name()))
          throw service::RpcError(int(grpc::StatusCode::DATA_LOSS),
                                  "the server named a result '" + f.name() + "': not a plain file name (or one folder and a plain file name)");
        if (f.name().find('/') != std::string::npos) fs::create_directories((into / f.name()).parent_path());
        client.download(job, f.name(), (into / f.name()).string());
        bytes += f.bytes();
        ++count;
      }
    };
    download_all(id, files, tmp);
    if (with_members) {
      if (j.members().total() == 0) return usage_error("runout fetch", "--members: job " + id + " is not an ensemble");
      for (const auto& m : client.members(id)) {
        if (m.state() != v1::SUCCEEDED) continue;  // a member that did not succeed has no results to fetch
        const fs::path into = tmp / "members" / ("member_" + std::to_string(m.member_index()));
        fs::create_directories(into);
        download_all(m.id(), client.results(m.id()), into);
      }
    }
    if (!staged.publish()) {
      std::cerr << "runout fetch: " << staged.error() << "\n";
      return kOutput;
    }
    if (!staged.note().empty()) std::cerr << "runout fetch: note: " << staged.note() << "\n";
    std::printf("%d file(s), %.2f MiB, checksums verified, in %s\n", count, double(bytes) / (1 << 20),
                dest.string().c_str());
    return j.state() == v1::SUCCEEDED ? kOk : code_of_state(j.state());
  } catch (const service::RpcError& e) {
    std::cerr << "runout fetch: " << e.what() << "\n";
    return code_of(e);
  }
}

int health(const std::vector<std::string>& args) {
  ClientApp c("Ask the server's standard health service (no token needed); exit 0 when serving, 7 otherwise.",
              "runout health");
  if (const int rc = c.parse(args); rc >= 0) return rc;
  try {
    service::Client client(c.opt);
    const bool ok = client.healthy();
    std::printf("%s %s\n", c.opt.server.c_str(), ok ? "SERVING" : "NOT_SERVING");
    return ok ? kOk : kService;
  } catch (const service::RpcError& e) {
    std::cerr << "runout health: " << e.what() << "\n";
    return kService;
  }
}

}  // namespace runout::cli
