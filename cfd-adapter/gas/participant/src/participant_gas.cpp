// The prescribed-gas participant's row of the participant table (participants.h) and its
// pre-flight: the case file's gas section through the gas model library.
#include <coredem/gas/gas_model.h>
#include <coredem/participant/gas.h>

namespace coredem::orchestrator {

ParticipantDescriptor gasParticipant() {
  // Prescribed gas from the case file (docs/client.md "coredem-gas"): verification cases,
  // DEM-only runs, tests. Everything on its command line; its restart file is gas.h5.
  ParticipantDescriptor p;
  p.name = "coredem-gas";
  p.summary = "prescribed gas fields from the case file's gas section";
  p.args = {"--case",    "{run_case_file}",    "--key",       "{gas_key}",
            "--control", "{control_endpoint}", "--dem",       "{dem_endpoint}",
            "--session", "{session}",          "--timeout-s", "{timeout_s}"};
  p.restartArgs = {"--restart", "{restart_file}"};
  p.env = {{"COREDEM_DEM_SERVER_KEY", "{dem_server_key}"},
           {"COREDEM_DEM_CLIENT_KEY_FILE", "{dem_client_key_file}"}};
  p.restartFile = "*.h5";
  p.preflight = &checkGasSection;
  return p;
}

void checkGasSection(const CaseConfig& config) {
  try {
    gas::GasModel::fromFile(config.caseFile.string(), config.cfd.gasKey);
  } catch (const UserError& e) {
    throw CaseError(e.what());
  }
}

} // namespace coredem::orchestrator
