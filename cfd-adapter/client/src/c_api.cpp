// The C API (coredem_client.h) over coredem::client::Participant.
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "coredem/client/coredem_client.h"
#include "coredem/client/participant.h"

using coredem::client::ClientError;
using coredem::client::ErrorCode;
using coredem::client::Participant;

struct coredem_client {
  coredem::client::Options options;
  std::unique_ptr<Participant> participant;
  std::string lastError;
  std::string checkpointDir; // keeps coredem_grant::checkpoint_dir alive
  std::string controlState;  // keeps coredem_client_control_state's string alive
};

namespace {

coredem_status toStatus(ErrorCode c) {
  switch (c) {
  case ErrorCode::Argument:
    return COREDEM_ERROR_ARGUMENT;
  case ErrorCode::State:
    return COREDEM_ERROR_STATE;
  case ErrorCode::Protocol:
    return COREDEM_ERROR_PROTOCOL;
  case ErrorCode::Timeout:
    return COREDEM_ERROR_TIMEOUT;
  case ErrorCode::Peer:
    return COREDEM_ERROR_PEER;
  case ErrorCode::Internal:
    return COREDEM_ERROR_INTERNAL;
  }
  return COREDEM_ERROR_INTERNAL;
}

/// Runs f on a valid handle; records the error message.
template <class F>
coredem_status call(coredem_client* c, const char* name, F&& f) {
  if (c == nullptr) {
    return COREDEM_ERROR_ARGUMENT;
  }
  try {
    f();
    c->lastError.clear();
    return COREDEM_OK;
  } catch (const ClientError& e) {
    c->lastError = e.what();
    return toStatus(e.code());
  } catch (const std::exception& e) {
    c->lastError = std::string(name) + ": internal error: " + e.what();
    return COREDEM_ERROR_INTERNAL;
  }
}

void argCheck(bool ok, const std::string& message) {
  if (!ok) {
    throw ClientError(ErrorCode::Argument, message);
  }
}

Participant& participant(coredem_client* c) {
  if (!c->participant) {
    throw coredem::client::StateError("the handle was finalized or never created a participant");
  }
  return *c->participant;
}

} // namespace

extern "C" {

coredem_status coredem_client_create(const char* control_endpoint, const char* dem_endpoint,
                                     const char* session_id, coredem_client** out) {
  if (out == nullptr) {
    return COREDEM_ERROR_ARGUMENT;
  }
  *out = new (std::nothrow) coredem_client();
  if (*out == nullptr) {
    return COREDEM_ERROR_INTERNAL;
  }
  auto* c = *out;
  return call(c, "coredem_client_create", [&] {
    c->options.controlEndpoint = control_endpoint != nullptr ? control_endpoint : "";
    c->options.demEndpoint = dem_endpoint != nullptr ? dem_endpoint : "";
    c->options.sessionId = session_id != nullptr ? session_id : "";
    c->options.name = "cfd (C API)";
    c->participant = std::make_unique<Participant>(c->options);
  });
}

coredem_status coredem_client_set_timeout(coredem_client* c, double seconds) {
  return call(c, "coredem_client_set_timeout", [&] {
    argCheck(seconds > 0.0, "coredem_client_set_timeout: seconds must be > 0");
    if (participant(c).state() != coredem::client::State::Created) {
      throw coredem::client::StateError("coredem_client_set_timeout: call it before initialize");
    }
    c->options.timeoutSeconds = seconds;
    c->participant = std::make_unique<Participant>(c->options);
  });
}

coredem_status coredem_client_set_rank(coredem_client* c, int32_t rank, int32_t rank_count) {
  return call(c, "coredem_client_set_rank", [&] {
    argCheck(rank >= 0 && rank_count >= 0 && (rank_count <= 1 ? rank == 0 : rank < rank_count),
             "coredem_client_set_rank: rank " + std::to_string(rank) + " of " +
                 std::to_string(rank_count) + ": the rank must lie in [0, rank_count)");
    if (participant(c).state() != coredem::client::State::Created) {
      throw coredem::client::StateError(
          "coredem_client_set_rank: call it before initialize/follow");
    }
    c->options.rank = rank;
    c->options.rankCount = rank_count;
    c->participant = std::make_unique<Participant>(c->options);
  });
}

coredem_status coredem_client_control_state(coredem_client* c, const char** state, size_t* size) {
  return call(c, "coredem_client_control_state", [&] {
    argCheck(state != nullptr && size != nullptr,
             "coredem_client_control_state: state and size must not be NULL");
    c->controlState = participant(c).controlState();
    *state = c->controlState.c_str();
    *size = c->controlState.size();
  });
}

coredem_status coredem_client_follow(coredem_client* c, const char* state, size_t size) {
  return call(c, "coredem_client_follow", [&] {
    argCheck(state != nullptr || size == 0, "coredem_client_follow: state is NULL");
    participant(c).follow(std::string(state != nullptr ? state : "", size));
  });
}

coredem_status coredem_client_exchange_partial(coredem_client* c, int64_t step, double dt,
                                               int64_t n_cells, const int64_t* cells,
                                               const double* fluid_volume, int32_t n_fields,
                                               const char* const* names,
                                               const double* const* values, const size_t* sizes) {
  return call(c, "coredem_client_exchange_partial", [&] {
    argCheck(n_cells >= 0 && (n_cells == 0 || (cells != nullptr && fluid_volume != nullptr)),
             "coredem_client_exchange_partial: cells and fluid_volume must hold n_cells entries");
    argCheck(n_fields >= 0 &&
                 (n_fields == 0 || (names != nullptr && values != nullptr && sizes != nullptr)),
             "coredem_client_exchange_partial: names, values and sizes must hold n_fields entries");
    std::vector<coredem::client::NamedField> fields;
    for (int32_t i = 0; i < n_fields; ++i) {
      argCheck(names[i] != nullptr,
               "coredem_client_exchange_partial: names[" + std::to_string(i) + "] is NULL");
      fields.push_back({names[i], coredem::client::ConstView(values[i], sizes[i])});
    }
    const std::vector<std::int64_t> list(cells, cells + n_cells);
    participant(c).exchangePartial(
        step, dt, list, coredem::client::ConstView(fluid_volume, std::size_t(n_cells)), fields);
  });
}

coredem_status coredem_client_initialize(coredem_client* c) {
  return call(c, "coredem_client_initialize", [&] { participant(c).initialize(); });
}

coredem_state coredem_client_state(const coredem_client* c) {
  if (c == nullptr || !c->participant) {
    return COREDEM_STATE_FINALIZED;
  }
  return static_cast<coredem_state>(static_cast<int>(c->participant->state()));
}

int coredem_client_is_running(const coredem_client* c) {
  return c != nullptr && c->participant && c->participant->isRunning() ? 1 : 0;
}

coredem_status coredem_client_grant(const coredem_client* cc, coredem_grant* out) {
  auto* c = const_cast<coredem_client*>(cc);
  return call(c, "coredem_client_grant", [&] {
    argCheck(out != nullptr, "coredem_client_grant: out is NULL");
    auto& p = participant(c);
    out->step = p.step();
    out->time = p.time();
    out->dt = p.dt();
    out->n_sub = p.nSub();
    out->dt_dem = p.dtDem();
    c->checkpointDir = p.checkpointDir();
    out->requires_checkpoint = c->checkpointDir.empty() ? 0 : 1;
    out->checkpoint_dir = c->checkpointDir.c_str();
  });
}

coredem_status coredem_client_requires_output(const coredem_client* cc, int* out) {
  auto* c = const_cast<coredem_client*>(cc);
  return call(c, "coredem_client_requires_output", [&] {
    argCheck(out != nullptr, "coredem_client_requires_output: out is NULL");
    *out = participant(c).requiresOutput() ? 1 : 0;
  });
}

coredem_status coredem_client_grid(const coredem_client* cc, coredem_grid* out) {
  auto* c = const_cast<coredem_client*>(cc);
  return call(c, "coredem_client_grid", [&] {
    argCheck(out != nullptr, "coredem_client_grid: out is NULL");
    const auto& g = participant(c).grid();
    for (int a = 0; a < 3; ++a) {
      out->origin[a] = g.origin[a];
      out->spacing[a] = g.spacing[a];
      out->counts[a] = g.counts[a];
    }
    out->cell_count = g.cellCount();
    out->species_count = static_cast<int32_t>(g.species.size());
  });
}

coredem_status coredem_client_species_name(const coredem_client* cc, int32_t k, const char** name) {
  auto* c = const_cast<coredem_client*>(cc);
  return call(c, "coredem_client_species_name", [&] {
    argCheck(name != nullptr, "coredem_client_species_name: name is NULL");
    const auto& g = participant(c).grid();
    argCheck(k >= 0 && static_cast<std::size_t>(k) < g.species.size(),
             "coredem_client_species_name: k = " + std::to_string(k) + " is not in [0, " +
                 std::to_string(g.species.size()) + ")");
    *name = g.species[static_cast<std::size_t>(k)].c_str();
  });
}

coredem_status coredem_client_exchange(coredem_client* c, int64_t step, double dt, int32_t n_fields,
                                       const char* const* names, const double* const* values,
                                       const size_t* sizes) {
  return call(c, "coredem_client_exchange", [&] {
    argCheck(n_fields >= 0 &&
                 (n_fields == 0 || (names != nullptr && values != nullptr && sizes != nullptr)),
             "coredem_client_exchange: names, values and sizes must hold n_fields entries");
    std::vector<coredem::client::NamedField> fields;
    for (int32_t i = 0; i < n_fields; ++i) {
      argCheck(names[i] != nullptr,
               "coredem_client_exchange: names[" + std::to_string(i) + "] is NULL");
      fields.push_back({names[i], coredem::client::ConstView(values[i], sizes[i])});
    }
    participant(c).exchange(step, dt, fields);
  });
}

coredem_status coredem_client_source(const coredem_client* cc, const char* name,
                                     const double** values, size_t* size) {
  auto* c = const_cast<coredem_client*>(cc);
  return call(c, "coredem_client_source", [&] {
    argCheck(name != nullptr && values != nullptr && size != nullptr,
             "coredem_client_source: name, values and size must not be NULL");
    const auto v = participant(c).sources().field(name);
    *values = v.data;
    *size = v.size;
  });
}

coredem_status coredem_client_radiation_heat(const coredem_client* cc, const double** values,
                                             size_t* size) {
  auto* c = const_cast<coredem_client*>(cc);
  return call(c, "coredem_client_radiation_heat", [&] {
    argCheck(values != nullptr && size != nullptr,
             "coredem_client_radiation_heat: values and size must not be NULL");
    const auto v = participant(c).sources().radiationHeat();
    *values = v.size > 0 ? v.data : nullptr;
    *size = v.size;
  });
}

coredem_status coredem_client_released_momentum(const coredem_client* cc, const double** values,
                                                size_t* size) {
  auto* c = const_cast<coredem_client*>(cc);
  return call(c, "coredem_client_released_momentum", [&] {
    argCheck(values != nullptr && size != nullptr,
             "coredem_client_released_momentum: values and size must not be NULL");
    const auto v = participant(c).sources().releasedMomentum();
    *values = v.size > 0 ? v.data : nullptr;
    *size = v.size;
  });
}

coredem_status coredem_client_set_heat_to_particles(coredem_client* c, const double* values,
                                                    size_t size) {
  return call(c, "coredem_client_set_heat_to_particles", [&] {
    argCheck(size == 0 || values != nullptr,
             "coredem_client_set_heat_to_particles: values must not be NULL");
    participant(c).setHeatToParticles(coredem::client::ConstView(values, size));
  });
}

coredem_status coredem_client_advance(coredem_client* c, double courant, int32_t n_ledgers,
                                      const char* const* ledger_names, const double* ledger_values,
                                      int32_t n_files, const char* const* checkpoint_files) {
  return call(c, "coredem_client_advance", [&] {
    argCheck(n_ledgers >= 0 &&
                 (n_ledgers == 0 || (ledger_names != nullptr && ledger_values != nullptr)),
             "coredem_client_advance: ledger_names and ledger_values must hold n_ledgers entries");
    argCheck(n_files >= 0 && (n_files == 0 || checkpoint_files != nullptr),
             "coredem_client_advance: checkpoint_files must hold n_files entries");
    coredem::client::Ledgers l;
    for (int32_t i = 0; i < n_ledgers; ++i) {
      argCheck(ledger_names[i] != nullptr,
               "coredem_client_advance: ledger_names[" + std::to_string(i) + "] is NULL");
      l.energy.emplace_back(ledger_names[i], ledger_values[i]);
    }
    std::vector<std::string> files;
    for (int32_t i = 0; i < n_files; ++i) {
      argCheck(checkpoint_files[i] != nullptr,
               "coredem_client_advance: checkpoint_files[" + std::to_string(i) + "] is NULL");
      files.emplace_back(checkpoint_files[i]);
    }
    participant(c).advance(courant, l, files);
  });
}

coredem_status coredem_client_finalize(coredem_client* c) {
  return call(c, "coredem_client_finalize", [&] { participant(c).finalize(); });
}

void coredem_client_destroy(coredem_client* c) {
  delete c;
}

const char* coredem_client_last_error(const coredem_client* c) {
  return c == nullptr ? "NULL handle" : c->lastError.c_str();
}

const char* coredem_status_name(coredem_status s) {
  switch (s) {
  case COREDEM_OK:
    return "OK";
  case COREDEM_ERROR_ARGUMENT:
    return "ERROR_ARGUMENT";
  case COREDEM_ERROR_STATE:
    return "ERROR_STATE";
  case COREDEM_ERROR_PROTOCOL:
    return "ERROR_PROTOCOL";
  case COREDEM_ERROR_TIMEOUT:
    return "ERROR_TIMEOUT";
  case COREDEM_ERROR_PEER:
    return "ERROR_PEER";
  case COREDEM_ERROR_INTERNAL:
    return "ERROR_INTERNAL";
  }
  return "UNKNOWN";
}

} // extern "C"
