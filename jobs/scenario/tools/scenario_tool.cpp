// runout_scenario_tool: what the scenario tables produce, for people and for tests.
//   runout_scenario_tool reference        the scenario reference page (docs/user/scenario-reference.md)
//   runout_scenario_tool hashes FILE...   the scenario hash of each file (one "hash  file" line each)
#include <cstdio>
#include <cstring>
#include <string>

#include "jobs/scenario/options.hpp"
#include "jobs/scenario/scenario.hpp"

int main(int argc, char** argv) {
  using namespace runout;
  if (argc == 2 && std::strcmp(argv[1], "reference") == 0) {
    std::fputs(jobs::scenario_reference_markdown().c_str(), stdout);
    return 0;
  }
  if (argc >= 2 && std::strcmp(argv[1], "hashes") == 0) {
    int rc = 0;
    for (int k = 2; k < argc; ++k) {
      try {
        std::printf("%s  %s\n", jobs::scenario_hash(jobs::load_scenario(argv[k])).c_str(), argv[k]);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", argv[k], e.what());
        rc = 1;
      }
    }
    return rc;
  }
  std::fprintf(stderr, "usage: runout_scenario_tool reference | hashes FILE...\n");
  return 2;
}
