#pragma once
/// @file
/// `coredem-bench <command> [options]`: each benchmark command registers itself here from
/// its own source file under bench/commands/ with COREDEM_BENCH_COMMAND.

#include <functional>
#include <map>
#include <string>

namespace coredem::bench {

using Command = std::function<int(int argc, char** argv)>;

struct CommandInfo {
  std::string summary;
  Command run;
};

std::map<std::string, CommandInfo>& commands();

struct Registrar {
  Registrar(const std::string& name, const std::string& summary, Command run) {
    commands()[name] = CommandInfo{summary, std::move(run)};
  }
};

} // namespace coredem::bench

/// Registers `int fn(int argc, char** argv)` as `coredem-bench NAME`; argv[0] is NAME.
#define COREDEM_BENCH_COMMAND(name, summary, fn)                                                   \
  static ::coredem::bench::Registrar coredemBenchRegistrar_##fn {                                  \
    name, summary, fn                                                                              \
  }
