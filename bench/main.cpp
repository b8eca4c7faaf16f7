// coredem-bench: benchmarks of CoReDEM's parts. Figures are printed, never asserted.
#include <cstdio>
#include <cstring>

#include "commands.h"

namespace coredem::bench {
std::map<std::string, CommandInfo>& commands() {
  static std::map<std::string, CommandInfo> table;
  return table;
}
} // namespace coredem::bench

int main(int argc, char** argv) {
  auto& table = coredem::bench::commands();
  auto usage = [&](FILE* out) {
    std::fprintf(out, "usage: coredem-bench <command> [options]   (<command> --help for its "
                      "options)\n\ncommands:\n");
    for (const auto& [name, info] : table) {
      std::fprintf(out, "  %-12s %s\n", name.c_str(), info.summary.c_str());
    }
  };
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  auto it = table.find(argv[1]);
  if (it == table.end()) {
    std::fprintf(stderr, "coredem-bench: unknown command '%s'\n\n", argv[1]);
    usage(stderr);
    return 2;
  }
  return it->second.run(argc - 1, argv + 1);
}
