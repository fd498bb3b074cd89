#pragma once
// SHA-256 (OpenSSL) for content hashes: scenario hashes, input files, uploads, downloads, tokens.
#include <memory>
#include <string>
#include <string_view>

namespace runout::jobs {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void update(std::string_view bytes);
  /// Lower-case hex digest; the object is spent afterwards.
  std::string hex();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Hex SHA-256 of a string.
std::string sha256_hex(std::string_view bytes);
/// Hex SHA-256 of a file's bytes; std::invalid_argument naming the file when it cannot be read.
std::string sha256_file(const std::string& path);

}  // namespace runout::jobs
