#pragma once
/// @file
/// How the DEM server reads Configure.initial_state_file, carried in an existing field: the
/// Configure option kInitialStateOption. Absent (or "resume"): the file is a checkpoint of this
/// same run, read bit for bit (time, ledgers, contact history), and its configuration hash must
/// be the server's. kInitialStateStart ("start"): a new run starts from the particles of another
/// run's state file (a checkpoint or a snapshot) with any configuration: time and ledgers start
/// at 0, materials are matched by name, the walls' contact history is dropped (docs/protocol.md,
/// case.yaml `initial_state`). A server that predates the option logs it as unknown and applies
/// the hash check, which names the mismatch.
#include <string_view>

namespace coredem::protocol::fields {

inline constexpr std::string_view kInitialStateOption = "initial_state";
inline constexpr std::string_view kInitialStateStart = "start";

} // namespace coredem::protocol::fields
