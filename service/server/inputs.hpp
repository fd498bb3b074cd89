#pragma once
// What the server takes from a client as input: files named by path (inside a data root, or an
// upload), in formats that cannot point elsewhere, and scenarios checked as `runout run` checks them,
// in a worker process of their own.
#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "runout/v1/scenario.pb.h"
#include "runout/v1/service.pb.h"

namespace runout::service {

/// A file's text; throws ConfigError naming it.
std::string read_text(const std::string& path);
/// 64 hexadecimal digits (an upload id, a SHA-256).
bool is_hex64(const std::string& s);
/// A plain file name: letters, digits, '.', '_', '-', not starting with '.', at most 200 characters.
bool plain_name(const std::string& n);
/// `p` lies inside `root` (both normalised; no file system access).
bool inside(const std::filesystem::path& p, const std::filesystem::path& root);
/// A scenario's input path on this server: an uploaded file (upload:ID/NAME) or a file inside a
/// data root, replaced by its path here; INVALID_ARGUMENT or NOT_FOUND naming `field` otherwise.
grpc::Status resolve_input(const v1::ServerConfig& cfg, const std::string& field, std::string* path);
/// Only formats that cannot point at other files or URLs (no VRT, no /vsi paths inside).
grpc::Status allowed_format(const std::string& field, const std::string& path);
/// A submission is refused (RESOURCE_EXHAUSTED) while the state directory's disk has less than
/// this free [bytes]: its check, its record and its job could not be written.
inline constexpr std::int64_t kMinFreeBytes = 1 << 20;
/// The refusal of a submission or upload for a full disk (OK while there is room). `why`: what
/// failed, when something did ("" for the check before anything is written).
grpc::Status full_disk(const v1::ServerConfig& cfg, const std::string& why = "");
/// The longest a submission's check may take; a longer one is accepted and checked by its job.
inline constexpr double kValidateSeconds = 30;
/// Every check `runout run` makes (fields, inputs read, grid or mesh built, one step), in a worker
/// process of its own: a DEM that crashes or hangs GDAL takes only that process down.
/// `stop` true ends the check (UNAVAILABLE: the server is stopping).
grpc::Status check_in_worker(const v1::ServerConfig& cfg, const v1::Scenario& s, const std::function<void(const std::string&)>& log,
                             const std::function<bool()>& stop = {});

}  // namespace runout::service
