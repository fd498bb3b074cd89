#pragma once
#include <openssl/crypto.h>
#include <sys/stat.h>

#include <array>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "jobs/digest/sha256.hpp"
#include "service/server/inputs.hpp"
#include "service/server/server.hpp"

namespace runout::service {

inline std::array<unsigned char, 32> digest_of(const std::string& hex) {
  std::array<unsigned char, 32> d{};
  for (std::size_t k = 0; k < 32; ++k) d[k] = static_cast<unsigned char>(std::stoi(hex.substr(2 * k, 2), nullptr, 16));
  return d;
}

// Bearer tokens from a file: one per line, the token itself or "sha256:HEX"; '#' starts a comment
// line. Only digests are kept; a presented token is hashed and compared with every digest in
// constant time. The file is read again when it changes (token rotation without a restart; a change
// is its size, times or inode). It fails closed: a file that cannot be read, holds no token or has a
// malformed line makes every token invalid until it is fixed, and the log says why.
class Tokens {
 public:
  Tokens(std::string path, std::function<void(const std::string&)> log) : path_(std::move(path)), log_(std::move(log)) {
    if (!path_.empty()) {
      std::lock_guard lk(mu_);
      digests_ = parse();  // at the start a bad file is an error (ConfigError)
      stamp_ = stamp();
    }
  }
  bool enabled() const { return !path_.empty(); }
  /// The owner id of a token ("t" + 16 hex digits of its digest), or "" when it is not known.
  std::string owner_of(const std::string& token) {
    std::lock_guard lk(mu_);
    const std::string now = stamp();
    if (now != stamp_) {
      stamp_ = now;
      try {
        digests_ = parse();
        if (log_) log_("tokens file '" + path_ + "' read again: " + std::to_string(digests_.size()) + " token(s)");
      } catch (const std::exception& e) {
        digests_.clear();  // fail closed
        if (log_) log_(std::string("tokens file: ") + e.what() + "; no token is accepted until it is fixed");
      }
    }
    const auto d = digest_of(jobs::sha256_hex(token));
    bool found = false;
    for (const auto& k : digests_) found |= CRYPTO_memcmp(k.data(), d.data(), d.size()) == 0;
    if (!found) return "";
    static const char* hex = "0123456789abcdef";
    std::string o = "t";
    for (int k = 0; k < 8; ++k) {
      o += hex[d[k] >> 4];
      o += hex[d[k] & 15];
    }
    return o;
  }

 private:
  // What identifies the file's version: inode, size, modification and change times ("" when gone).
  std::string stamp() const {
    struct stat st {};
    if (::stat(path_.c_str(), &st) != 0) return "";
    return std::to_string(st.st_ino) + ":" + std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) + "." +
           std::to_string(st.st_mtim.tv_nsec) + ":" + std::to_string(st.st_ctim.tv_sec) + "." + std::to_string(st.st_ctim.tv_nsec);
  }
  std::vector<std::array<unsigned char, 32>> parse() const {
    std::ifstream in(path_);
    if (!in) throw ConfigError("tokens_file '" + path_ + "': cannot read it");
    std::vector<std::array<unsigned char, 32>> ds;
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
      std::size_t b = line.find_first_not_of(" \t");
      if (b == std::string::npos || line[b] == '#') continue;
      line = line.substr(b);
      if (line.rfind("sha256:", 0) == 0) {
        const std::string h = line.substr(7);
        if (!is_hex64(h))
          throw ConfigError("tokens_file '" + path_ + "' line " + std::to_string(n) + ": sha256: needs 64 hex digits");
        std::string lower = h;
        for (auto& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
        ds.push_back(digest_of(lower));
      } else {
        ds.push_back(digest_of(jobs::sha256_hex(line)));
      }
    }
    if (ds.empty()) throw ConfigError("tokens_file '" + path_ + "' holds no token");
    return ds;
  }
  std::string path_;
  std::function<void(const std::string&)> log_;
  std::vector<std::array<unsigned char, 32>> digests_;
  std::string stamp_;
  std::mutex mu_;
};

}  // namespace runout::service
