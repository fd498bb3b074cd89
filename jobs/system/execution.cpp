#include "jobs/system/execution.hpp"

namespace runout::jobs {

namespace {
constexpr std::size_t kMaxEventBytes = 64u << 20;
}  // namespace

std::optional<v1::WorkerEvent> take_event(std::string& buf, bool& closed) {
  while (buf.size() >= 4) {
    const auto* u = reinterpret_cast<const unsigned char*>(buf.data());
    const std::size_t n = std::size_t(u[0]) | std::size_t(u[1]) << 8 | std::size_t(u[2]) << 16 | std::size_t(u[3]) << 24;
    if (n > kMaxEventBytes) {
      buf.clear();
      closed = true;
      return std::nullopt;
    }
    if (buf.size() < 4 + n) break;
    v1::WorkerEvent ev;
    const bool ok = ev.ParseFromArray(buf.data() + 4, int(n));
    buf.erase(0, 4 + n);
    if (ok) return ev;
  }
  return std::nullopt;
}

}  // namespace runout::jobs
