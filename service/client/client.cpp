#include "service/client/client.hpp"
#include "jobs/scenario/inputs.hpp"

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "grpc/health/v1/health.grpc.pb.h"
#include "jobs/digest/sha256.hpp"
#include "jobs/system/store.hpp"
#include "runout/v1/service.grpc.pb.h"

namespace fs = std::filesystem;

namespace runout::service {

std::string state_word(v1::JobState s) { return jobs::state_name(s); }

bool result_name_ok(const std::string& name) {
  auto plain = [](const std::string& p) { return !p.empty() && p[0] != '.' && p.find_first_of("/\\") == std::string::npos; };
  const auto slash = name.find('/');
  if (slash == std::string::npos) return plain(name);
  return plain(name.substr(0, slash)) && plain(name.substr(slash + 1));
}

struct Client::Impl {
  ClientOptions opt;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::Runout::Stub> stub;

  void prepare(grpc::ClientContext& ctx, bool deadline = true) const {
    if (!opt.token.empty()) ctx.AddMetadata("authorization", "Bearer " + opt.token);
    if (deadline)
      ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(long(opt.timeout_s * 1000)));
  }
  static void check(const grpc::Status& st, const std::string& what) {
    if (st.ok()) return;
    std::string m = st.error_message();
    if (st.error_code() == grpc::StatusCode::UNAVAILABLE) m = "cannot reach the server (" + m + ")";
    throw RpcError(int(st.error_code()), what + ": " + m);
  }
};

Client::Client(const ClientOptions& o) : impl_(std::make_unique<Impl>()) {
  impl_->opt = o;
  std::shared_ptr<grpc::ChannelCredentials> creds;
  if (!o.tls_ca.empty() || o.tls) {
    grpc::SslCredentialsOptions so;
    if (!o.tls_ca.empty()) {
      std::ifstream in(o.tls_ca);
      if (!in) throw RpcError(int(grpc::StatusCode::INVALID_ARGUMENT), "--tls-ca '" + o.tls_ca + "': cannot read it");
      std::stringstream ss;
      ss << in.rdbuf();
      so.pem_root_certs = ss.str();
    }
    creds = grpc::SslCredentials(so);
  } else {
    creds = grpc::InsecureChannelCredentials();
  }
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(64 << 20);
  impl_->channel = grpc::CreateCustomChannel(o.server, creds, args);
  impl_->stub = v1::Runout::NewStub(impl_->channel);
}

Client::~Client() = default;

v1::UploadResponse Client::upload(const std::vector<std::string>& files) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx, false);
  v1::UploadResponse resp;
  auto w = impl_->stub->UploadInput(&ctx, &resp);
  std::string buf(256 << 10, '\0');  // well below the server's smallest message limit
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    if (!in) throw RpcError(int(grpc::StatusCode::INVALID_ARGUMENT), "cannot read '" + f + "' to upload it");
    bool any = false;
    while (in || !any) {
      in.read(buf.data(), std::streamsize(buf.size()));
      v1::UploadChunk c;
      c.set_file_name(fs::path(f).filename().string());
      c.set_data(buf.data(), std::size_t(in.gcount()));
      any = true;
      if (!w->Write(c)) break;
      if (!in) break;
    }
  }
  w->WritesDone();
  Impl::check(w->Finish(), "upload of '" + (files.empty() ? std::string() : files.front()) + "'");
  return resp;
}

v1::Job Client::submit(const v1::Scenario& s, const std::string& request_id) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx);
  v1::SubmitRequest req;
  *req.mutable_scenario() = s;
  req.set_request_id(request_id);
  v1::Job j;
  Impl::check(impl_->stub->SubmitScenario(&ctx, req, &j), "submit");
  return j;
}

v1::Job Client::get(const std::string& id) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx);
  v1::GetJobRequest req;
  req.set_id(id);
  v1::Job j;
  Impl::check(impl_->stub->GetJob(&ctx, req, &j), "job " + id);
  return j;
}

v1::ListJobsResponse Client::list(const std::vector<v1::JobState>& states, int page_size, const std::string& page_token) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx);
  v1::ListJobsRequest req;
  for (auto s : states) req.add_states(s);
  req.set_page_size(page_size);
  req.set_page_token(page_token);
  v1::ListJobsResponse r;
  Impl::check(impl_->stub->ListJobs(&ctx, req, &r), "list jobs");
  return r;
}

std::vector<v1::Job> Client::members(const std::string& parent_id) {
  std::vector<v1::Job> out;
  std::string token;
  do {
    grpc::ClientContext ctx;
    impl_->prepare(ctx);
    v1::ListJobsRequest req;
    req.set_parent_id(parent_id);
    req.set_page_size(500);
    req.set_page_token(token);
    v1::ListJobsResponse r;
    Impl::check(impl_->stub->ListJobs(&ctx, req, &r), "list the ensemble's members");
    for (auto& j : *r.mutable_jobs()) out.push_back(std::move(j));
    token = r.next_page_token();
  } while (!token.empty());
  return out;
}

v1::Job Client::cancel(const std::string& id) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx);
  v1::CancelJobRequest req;
  req.set_id(id);
  v1::Job j;
  Impl::check(impl_->stub->CancelJob(&ctx, req, &j), "cancel " + id);
  return j;
}

v1::Job Client::watch(const std::string& id, const std::function<void(const v1::Job&)>& on_event) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx, false);
  if (impl_->opt.watch_timeout_s > 0)
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(long(impl_->opt.watch_timeout_s * 1000)));
  v1::WatchJobRequest req;
  req.set_id(id);
  auto r = impl_->stub->WatchJob(&ctx, req);
  v1::JobEvent ev;
  v1::Job last;
  while (r->Read(&ev)) {
    last = ev.job();
    if (on_event) on_event(last);
  }
  Impl::check(r->Finish(), "watch " + id);
  return last;
}

v1::ListResultsResponse Client::results(const std::string& id) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx);
  v1::ListResultsRequest req;
  req.set_job_id(id);
  v1::ListResultsResponse r;
  Impl::check(impl_->stub->ListResults(&ctx, req, &r), "results of " + id);
  return r;
}

void Client::download(const std::string& id, const std::string& name, const std::string& dest) {
  grpc::ClientContext ctx;
  impl_->prepare(ctx, false);
  v1::DownloadResultRequest req;
  req.set_job_id(id);
  req.set_name(name);
  auto r = impl_->stub->DownloadResult(&ctx, req);
  const std::string part = dest + ".part";
  std::ofstream out(part, std::ios::binary);
  if (!out) throw RpcError(int(grpc::StatusCode::INVALID_ARGUMENT), "cannot write '" + part + "'");
  jobs::Sha256 h;
  std::string expected;
  v1::DataChunk c;
  while (r->Read(&c)) {
    out.write(c.data().data(), std::streamsize(c.data().size()));
    h.update(c.data());
    if (!c.sha256().empty()) expected = c.sha256();
  }
  out.close();
  const auto st = r->Finish();
  if (!st.ok()) {
    fs::remove(part);
    Impl::check(st, "download " + name);
  }
  if (expected.empty() || h.hex() != expected) {
    fs::remove(part);
    throw RpcError(int(grpc::StatusCode::DATA_LOSS), "download " + name + ": checksum mismatch");
  }
  fs::rename(part, dest);
}

bool Client::healthy() {
  auto stub = grpc::health::v1::Health::NewStub(impl_->channel);
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  grpc::health::v1::HealthCheckRequest req;
  grpc::health::v1::HealthCheckResponse resp;
  const auto st = stub->Check(&ctx, req, &resp);
  if (!st.ok()) throw RpcError(int(st.error_code()), "health check: " + st.error_message());
  return resp.status() == grpc::health::v1::HealthCheckResponse::SERVING;
}

v1::Scenario upload_inputs(Client& c, v1::Scenario s, const std::string& base_dir) {
  auto up = [&](std::string* path) {
    if (path->empty() || path->rfind("upload:", 0) == 0) return;
    fs::path p = *path;
    if (p.is_relative()) p = fs::path(base_dir) / p;
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))  // (a symbolic link loop is an error code, not an exception)
      throw RpcError(int(grpc::StatusCode::INVALID_ARGUMENT), "input '" + p.string() + "' does not exist or is not a file" +
                                                                 (ec ? " (" + ec.message() + ")" : std::string()));
    std::vector<std::string> files = {p.string()};
    for (const char* ext : {".shx", ".dbf", ".prj", ".cpg", ".qix", ".aux.xml", ".hdr", ".tfw"}) {
      fs::path side = p;
      side.replace_extension(ext);
      if (std::string(ext) == ".aux.xml") side = p.string() + ".aux.xml";
      if (side != p && fs::is_regular_file(side, ec)) files.push_back(side.string());
    }
    *path = c.upload(files).ref();
  };
  jobs::for_each_input_path(s, [&](const std::string&, std::string* path) { up(path); });
  return s;
}

}  // namespace runout::service
