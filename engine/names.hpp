#pragma once
// Models, limiters and boundary types are chosen by name from explicit tables.
// A misspelt name is an error that lists the valid ones.
#include <array>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace runout::engine {

template <class E, std::size_t N>
using NameTable = std::array<std::pair<std::string_view, E>, N>;

template <class E, std::size_t N>
E parse_name(const NameTable<E, N>& table, std::string_view what, std::string_view name) {
  for (const auto& [n, e] : table)
    if (n == name) return e;
  std::string valid;
  for (const auto& [n, e] : table) {
    if (!valid.empty()) valid += ", ";
    valid += n;
  }
  throw std::invalid_argument("unknown " + std::string(what) + " '" + std::string(name) +
                              "' (valid: " + valid + ")");
}

template <class E, std::size_t N>
std::string_view name_of(const NameTable<E, N>& table, E e) {
  for (const auto& [n, v] : table)
    if (v == e) return n;
  throw std::logic_error("a value missing from its name table");  // a table that misses one of its enum's values
}

}  // namespace runout::engine
