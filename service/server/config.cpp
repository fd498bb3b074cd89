// The server's configuration: defaults filled in and every key checked (ConfigError names the key).
#include <google/protobuf/util/json_util.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "jobs/system/scheduler.hpp"
#include "service/server/inputs.hpp"
#include "service/server/server.hpp"

namespace fs = std::filesystem;

namespace runout::service {

v1::ServerConfig resolve_config(v1::ServerConfig c) {
  if (c.listen().empty()) c.set_listen("127.0.0.1:50051");
  if (c.listen().find(':') == std::string::npos) throw ConfigError("listen: '" + c.listen() + "' is not HOST:PORT");
  if (c.state_dir().empty()) c.set_state_dir("runout-state");
  if (c.workers() == 0) c.set_workers(1);
  if (c.workers() < 0 || c.workers() > 256) throw ConfigError("workers: must lie in 1..256, got " + std::to_string(c.workers()));
  if (c.threads_per_run() < 0) throw ConfigError("threads_per_run: must be >= 0 (0: cores / workers)");
  if (c.max_queued_per_client() == 0) c.set_max_queued_per_client(100);
  if (c.max_queued_per_client() < 0) throw ConfigError("max_queued_per_client: must be > 0");
  if (c.max_upload_bytes() == 0) c.set_max_upload_bytes(std::int64_t(2) << 30);
  if (c.max_upload_bytes() < 0) throw ConfigError("max_upload_bytes: must be > 0");
  if (c.max_message_bytes() == 0) c.set_max_message_bytes(16 << 20);
  if (c.max_message_bytes() < (1 << 20)) throw ConfigError("max_message_bytes: must be at least 1048576");
  if (c.retention_days() < 0) throw ConfigError("retention_days: must be >= 0 (0: keep)");
  if (c.retention_max_bytes() < 0) throw ConfigError("retention_max_bytes: must be >= 0 (0: no limit)");
  if (c.tls_cert().empty() != c.tls_key().empty()) throw ConfigError("tls_cert and tls_key: give both or neither");
  if (c.max_job_wall_s() == 0) c.set_max_job_wall_s(86400);
  if (!(c.max_job_wall_s() > 0 && c.max_job_wall_s() <= 365 * 86400.0))
    throw ConfigError("max_job_wall_s: must lie in (0, 31536000] s");
  if (c.max_job_memory_bytes() == 0) {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0) c.set_max_job_memory_bytes(std::int64_t(pages) * page / std::max(1, c.workers()));
  }
  if (c.max_job_memory_bytes() < 0) throw ConfigError("max_job_memory_bytes: must be > 0");
  if (c.upload_ttl_s() == 0) c.set_upload_ttl_s(3600);
  if (!(c.upload_ttl_s() > 0 && std::isfinite(c.upload_ttl_s()))) throw ConfigError("upload_ttl_s: must be > 0 s");
  if (c.max_upload_bytes_per_client() == 0) c.set_max_upload_bytes_per_client(std::int64_t(8) << 30);
  if (c.max_upload_bytes_per_client() < 0) throw ConfigError("max_upload_bytes_per_client: must be > 0");
  if (c.stop_grace_s() == 0) c.set_stop_grace_s(1);
  if (!(c.stop_grace_s() > 0 && c.stop_grace_s() <= 600)) throw ConfigError("stop_grace_s: must lie in (0, 600] s");
  if (c.max_crashes() == 0) c.set_max_crashes(3);
  if (c.max_crashes() < 0 || c.max_crashes() > 100) throw ConfigError("max_crashes: must lie in 1..100");
  if (c.backend().empty()) c.set_backend("local");
  if (c.backend() != "local" && c.backend() != "slurm") throw ConfigError("backend: unknown '" + c.backend() + "' (valid: local, slurm)");
  if (c.max_ranks_per_job() == 0) c.set_max_ranks_per_job(c.backend() == "local" ? std::max(1, int(sysconf(_SC_NPROCESSORS_ONLN))) : 1024);
  if (c.max_ranks_per_job() < 1 || c.max_ranks_per_job() > 65536) throw ConfigError("max_ranks_per_job: must lie in 1..65536");
  if (c.mpi_launcher_size() == 0)
    for (const auto& a : jobs::SchedulerConfig{}.mpi_launcher) c.add_mpi_launcher(a);
  if (c.mpi_launcher(0).empty()) throw ConfigError("mpi_launcher: its first word is the launcher's command (default mpirun)");
  if (c.slurm_mpi().empty()) c.set_slurm_mpi("pmix");
  if (c.slurm_mpi().find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos)
    throw ConfigError("slurm_mpi: '" + c.slurm_mpi() + "' is not an MPI plugin's name (srun --mpi=list; \"cluster\": the cluster's default)");
  std::error_code ec;
  fs::create_directories(c.state_dir(), ec);
  if (ec) throw ConfigError("state_dir '" + c.state_dir() + "': " + ec.message());
  c.set_state_dir(fs::canonical(c.state_dir()).string());
  for (int k = 0; k < c.data_roots_size(); ++k) {
    const fs::path p = c.data_roots(k);
    if (!fs::is_directory(p, ec)) throw ConfigError("data_roots: '" + p.string() + "' is not a folder");
    c.set_data_roots(k, fs::canonical(p).string());
  }
  for (const auto* f : {&c.tokens_file(), &c.tls_cert(), &c.tls_key()})
    if (!f->empty() && !fs::is_regular_file(*f, ec)) throw ConfigError("'" + *f + "' does not exist or is not a file");
  return c;
}

v1::ServerConfig read_config_file(const std::string& path) {
  v1::ServerConfig c;
  google::protobuf::util::JsonParseOptions o;
  o.ignore_unknown_fields = false;
  const auto st = google::protobuf::util::JsonStringToMessage(read_text(path), &c, o);
  if (!st.ok()) throw ConfigError("configuration '" + path + "': " + std::string(st.message()));
  return c;
}

}  // namespace runout::service
