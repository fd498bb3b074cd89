// Client commands: submit, status, watch, cancel, fetch, health. Each talks to a server given by
// --server HOST:PORT (or RUNOUT_SERVER) with the bearer token of --token / --token-file (or
// RUNOUT_TOKEN).
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

#include "jobs/scenario.hpp"
#include "service/cli/commands.hpp"
#include "service/cli/output_dir.hpp"
#include "service/client/client.hpp"

namespace fs = std::filesystem;

namespace runout::cli {

namespace {

struct Common {
  service::ClientOptions opt;
  std::vector<std::string> rest;  // positional arguments and command options
};

// Takes the connection options out of `args`; returns false (after a message) on a bad one.
bool parse_common(const std::string& cmd, const std::vector<std::string>& args, Common* c) {
  if (const char* s = std::getenv("RUNOUT_SERVER")) c->opt.server = s;
  if (const char* t = std::getenv("RUNOUT_TOKEN")) c->opt.token = t;
  for (std::size_t k = 0; k < args.size(); ++k) {
    const auto& a = args[k];
    if (a == "--server" || a == "--token" || a == "--token-file" || a == "--tls-ca") {
      if (k + 1 >= args.size()) {
        std::cerr << "runout " << cmd << ": " << a << " needs a value\n";
        return false;
      }
      const std::string v = args[++k];
      if (a == "--server") c->opt.server = v;
      if (a == "--token") c->opt.token = v;
      if (a == "--tls-ca") c->opt.tls_ca = v;
      if (a == "--token-file") {
        std::ifstream in(v);
        std::string t;
        if (!in || !std::getline(in, t)) {
          std::cerr << "runout " << cmd << ": --token-file '" << v << "': cannot read a token from it\n";
          return false;
        }
        while (!t.empty() && (t.back() == '\r' || t.back() == ' ' || t.back() == '\t')) t.pop_back();
        c->opt.token = t;
      }
    } else if (a == "--tls") {
      c->opt.tls = true;
    } else {
      c->rest.push_back(a);
    }
  }
  return true;
}

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
  if (j.state() == v1::RUNNING) std::printf("progress   %s\n", progress_line(j).c_str());
  if (!j.error().empty()) std::printf("error      %s\n", j.error().c_str());
  if (j.result_bytes() > 0) std::printf("results    %.1f MiB\n", double(j.result_bytes()) / (1 << 20));
  std::printf("history\n");
  for (const auto& t : j.transitions())
    std::printf("  %s  %-9s  %s\n", t.time_utc().c_str(), service::state_word(t.state()).c_str(), t.reason().c_str());
}

}  // namespace

int submit(const std::vector<std::string>& args) {
  Common c;
  if (!parse_common("submit", args, &c)) return kUsage;
  std::string file, request_id;
  bool wait = false, server_paths = false, quiet = false;
  for (std::size_t k = 0; k < c.rest.size(); ++k) {
    const auto& a = c.rest[k];
    if (a == "--wait") {
      wait = true;
    } else if (a == "--quiet") {
      quiet = true;
    } else if (a == "--server-paths") {
      server_paths = true;
    } else if (a == "--request-id" && k + 1 < c.rest.size()) {
      request_id = c.rest[++k];
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "runout submit: unknown option '" << a << "' (see runout help)\n";
      return kUsage;
    } else if (file.empty()) {
      file = a;
    } else {
      std::cerr << "runout submit: one scenario per call ('" << file << "', '" << a << "')\n";
      return kUsage;
    }
  }
  if (file.empty()) {
    std::cerr << "runout submit: usage: runout submit SCENARIO.json [--wait] [--request-id ID] [--server-paths] [--server HOST:PORT] [--token TOKEN]\n";
    return kUsage;
  }
  v1::Scenario s;
  try {
    std::ifstream in(file);
    if (!in) throw jobs::ScenarioError("cannot read scenario '" + file + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    s = jobs::parse_scenario_json(ss.str());
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
  Common c;
  if (!parse_common("status", args, &c)) return kUsage;
  std::vector<v1::JobState> states;
  std::string id;
  for (std::size_t k = 0; k < c.rest.size(); ++k) {
    const auto& a = c.rest[k];
    if (a == "--state" && k + 1 < c.rest.size()) {
      const std::string v = c.rest[++k];
      v1::JobState s = v1::JOB_STATE_UNSPECIFIED;
      for (auto t : {v1::QUEUED, v1::RUNNING, v1::SUCCEEDED, v1::FAILED, v1::CANCELLED})
        if (service::state_word(t) == v) s = t;
      if (s == v1::JOB_STATE_UNSPECIFIED) {
        std::cerr << "runout status: unknown state '" << v << "' (valid: queued, running, succeeded, failed, cancelled)\n";
        return kUsage;
      }
      states.push_back(s);
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "runout status: unknown option '" << a << "' (see runout help)\n";
      return kUsage;
    } else {
      id = a;
    }
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
  Common c;
  if (!parse_common("watch", args, &c)) return kUsage;
  if (c.rest.size() != 1 || c.rest[0].empty() || c.rest[0][0] == '-') {
    std::cerr << "runout watch: usage: runout watch JOB [--server HOST:PORT] [--token TOKEN]\n";
    return kUsage;
  }
  try {
    service::Client client(c.opt);
    const auto j = follow(client, c.rest[0], false);
    std::printf("%s %s\n", j.id().c_str(), service::state_word(j.state()).c_str());
    if (!j.error().empty()) std::cerr << "runout watch: job " << j.id() << " failed: " << j.error() << "\n";
    return code_of_state(j.state());
  } catch (const service::RpcError& e) {
    std::cerr << "runout watch: " << e.what() << "\n";
    return code_of(e);
  }
}

int cancel(const std::vector<std::string>& args) {
  Common c;
  if (!parse_common("cancel", args, &c)) return kUsage;
  if (c.rest.size() != 1 || c.rest[0].empty() || c.rest[0][0] == '-') {
    std::cerr << "runout cancel: usage: runout cancel JOB [--server HOST:PORT] [--token TOKEN]\n";
    return kUsage;
  }
  try {
    service::Client client(c.opt);
    const auto j = client.cancel(c.rest[0]);
    std::printf("%s %s%s\n", j.id().c_str(), service::state_word(j.state()).c_str(),
                j.state() == v1::RUNNING ? " (cancel requested; it stops at its next progress point)" : "");
    return kOk;
  } catch (const service::RpcError& e) {
    std::cerr << "runout cancel: " << e.what() << "\n";
    return code_of(e);
  }
}

int fetch(const std::vector<std::string>& args) {
  Common c;
  if (!parse_common("fetch", args, &c)) return kUsage;
  std::string id, out;
  bool force = false;
  for (std::size_t k = 0; k < c.rest.size(); ++k) {
    const auto& a = c.rest[k];
    if (a == "--out" && k + 1 < c.rest.size()) {
      out = c.rest[++k];
    } else if (a == "--force") {
      force = true;
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "runout fetch: unknown option '" << a << "' (see runout help)\n";
      return kUsage;
    } else {
      id = a;
    }
  }
  if (id.empty() || out.empty()) {
    std::cerr << "runout fetch: usage: runout fetch JOB --out DIR [--force] [--server HOST:PORT] [--token TOKEN]\n";
    return kUsage;
  }
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
    for (const auto& f : files.files()) {
      if (f.name().empty() || f.name()[0] == '.' || f.name().find_first_of("/\\") != std::string::npos)
        throw service::RpcError(int(grpc::StatusCode::DATA_LOSS), "the server named a result '" + f.name() + "': not a plain file name");
      client.download(id, f.name(), (tmp / f.name()).string());
      bytes += f.bytes();
    }
    if (!staged.publish()) {
      std::cerr << "runout fetch: " << staged.error() << "\n";
      return kOutput;
    }
    if (!staged.note().empty()) std::cerr << "runout fetch: note: " << staged.note() << "\n";
    std::printf("%d file(s), %.2f MiB, checksums verified, in %s\n", files.files_size(), double(bytes) / (1 << 20),
                dest.string().c_str());
    return j.state() == v1::SUCCEEDED ? kOk : code_of_state(j.state());
  } catch (const service::RpcError& e) {
    std::cerr << "runout fetch: " << e.what() << "\n";
    return code_of(e);
  }
}

int health(const std::vector<std::string>& args) {
  Common c;
  if (!parse_common("health", args, &c)) return kUsage;
  if (!c.rest.empty()) {
    std::cerr << "runout health: unknown argument '" << c.rest[0] << "'\n";
    return kUsage;
  }
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
