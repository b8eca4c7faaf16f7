// The participant table (participants.h): every CFD participant that `coredem run` can start,
// one row each. A row and the hooks it points to are the participant's unit
// (cfd-adapter/<name>/participant, declared in coredem/participant/<name>.h); the case reader
// reads the rows (cfd.participant, cfd.case, cfd.timers, cfd.ranks, from_cfd, ideal_gas).
#include <coredem/orchestrator/participants.h>
#include <coredem/participant/gas.h>
#include <coredem/participant/openfoam.h>

namespace coredem::orchestrator {
namespace {

std::vector<ParticipantDescriptor> makeTable() {
  std::vector<ParticipantDescriptor> t;
  t.push_back(gasParticipant());      // cfd-adapter/gas/participant
  t.push_back(openFoamParticipant()); // cfd-adapter/openfoam/participant
  return t;
}

std::string joined(const std::vector<std::string>& items, const char* sep = ", ") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    out += (i ? sep : "") + items[i];
  }
  return out;
}

} // namespace

const std::vector<ParticipantDescriptor>& participantTable() {
  static const std::vector<ParticipantDescriptor> table = makeTable();
  return table;
}

std::vector<std::string> participantNames() {
  std::vector<std::string> names;
  for (const auto& p : participantTable()) {
    names.push_back(p.name);
  }
  return names;
}

const ParticipantDescriptor& participant(const std::string& name) {
  for (const auto& p : participantTable()) {
    if (p.name == name) {
      return p;
    }
  }
  throw CaseError(fmt::format("unknown CFD participant '{}'; known participants: {}", name,
                              joined(participantNames())));
}

} // namespace coredem::orchestrator
