/* The coupling client's C API (docs/client.md): the verbs of coredem::client::Participant on
 * an opaque handle, for C, Fortran (ISO_C_BINDING) and Python (ctypes) solvers.
 *
 *   coredem_client* c = NULL;
 *   if (coredem_client_create(NULL, NULL, NULL, &c) != COREDEM_OK) ...;   // environment
 *   if (coredem_client_initialize(c) != COREDEM_OK)
 *     fprintf(stderr, "%s\n", coredem_client_last_error(c));
 *   while (coredem_client_is_running(c)) {
 *     coredem_grant g; coredem_client_grant(c, &g);
 *     ... advance by g.dt ...
 *     coredem_client_exchange(c, g.step, g.dt, 8, names, values, sizes);
 *     const double* eps; size_t n; coredem_client_source(c, "eps_g", &eps, &n);
 *     coredem_client_advance(c, courant, 0, NULL, NULL, 0, NULL);
 *   }
 *   coredem_client_finalize(c);
 *   coredem_client_destroy(c);
 *
 * Every function returns COREDEM_OK (0) or an error status; the message of the last error is
 * coredem_client_last_error(handle). A call in the wrong order returns COREDEM_ERROR_STATE.
 * Pointers returned by the library stay valid until the next call on the same handle that
 * changes its state (exchange, advance, finalize, destroy). A handle is not thread-safe. */
#ifndef COREDEM_CLIENT_H
#define COREDEM_CLIENT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct coredem_client coredem_client;

typedef enum coredem_status {
  COREDEM_OK = 0,
  COREDEM_ERROR_ARGUMENT = 1, /* bad argument or environment */
  COREDEM_ERROR_STATE = 2,    /* call out of order */
  COREDEM_ERROR_PROTOCOL = 3, /* malformed/unexpected message */
  COREDEM_ERROR_TIMEOUT = 4,  /* a peer missed its deadline */
  COREDEM_ERROR_PEER = 5,     /* a peer answered Error/Reject */
  COREDEM_ERROR_INTERNAL = 6
} coredem_status;

typedef enum coredem_state {
  COREDEM_STATE_CREATED = 0,
  COREDEM_STATE_GRANTED = 1,
  COREDEM_STATE_EXCHANGED = 2,
  COREDEM_STATE_FINISHED = 3,
  COREDEM_STATE_FINALIZED = 4
} coredem_state;

/* The current grant (docs/session.md). */
typedef struct coredem_grant {
  int64_t step;               /* step number n */
  double time;                /* s, start of the step */
  double dt;                  /* s, Delta t_CFD: advance exactly this much */
  int32_t n_sub;              /* DEM sub-steps */
  double dt_dem;              /* s */
  int requires_checkpoint;    /* 1: write your state after this step into checkpoint_dir */
  const char* checkpoint_dir; /* "" when not requested */
} coredem_grant;

/* The coupling grid from Configure; cell = i + nx*(j + ny*k). */
typedef struct coredem_grid {
  double origin[3];  /* m */
  double spacing[3]; /* m */
  int64_t counts[3];
  int64_t cell_count;
  int32_t species_count;
} coredem_grid;

/* NULL/empty arguments are read from COREDEM_CONTROL_ENDPOINT, COREDEM_DEM_ENDPOINT and
 * COREDEM_SESSION when initialize() runs. *out receives the handle (also on error, so that
 * last_error can be read; destroy it in every case). */
coredem_status coredem_client_create(const char* control_endpoint, const char* dem_endpoint,
                                     const char* session_id, coredem_client** out);
/* Per-request deadline in seconds (default: COREDEM_TIMEOUT_S or 60). Before initialize. */
coredem_status coredem_client_set_timeout(coredem_client* c, double seconds);
coredem_status coredem_client_initialize(coredem_client* c);
/* Decomposed CFD (protocol 1.2, docs/client.md "Decomposed CFD"): this process is rank `rank` of
 * `rank_count` (rank_count <= 1: not decomposed). Before initialize/follow. Rank 0 calls
 * initialize and advance and hands control_state to the other ranks, which call follow instead;
 * every rank exchanges its own cells with exchange_partial. */
coredem_status coredem_client_set_rank(coredem_client* c, int32_t rank, int32_t rank_count);
/* Rank 0: the state the other ranks follow, *state valid until the next call on this handle. */
coredem_status coredem_client_control_state(coredem_client* c, const char** state, size_t* size);
/* Ranks > 0: take rank 0's control state (first call: this rank's initialize). */
coredem_status coredem_client_follow(coredem_client* c, const char* state, size_t size);

coredem_state coredem_client_state(const coredem_client* c);
/* 1 while O keeps granting steps, else 0. */
int coredem_client_is_running(const coredem_client* c);
coredem_status coredem_client_grant(const coredem_client* c, coredem_grant* out);
/* *out = 1 when the current grant asks for the participant's output fields after this step
 * (synchronized outputs, docs/client.md), else 0. */
coredem_status coredem_client_requires_output(const coredem_client* c, int* out);
coredem_status coredem_client_grid(const coredem_client* c, coredem_grid* out);
/* Name of species k (0 <= k < species_count). */
coredem_status coredem_client_species_name(const coredem_client* c, int32_t k, const char** name);

/* Sends n_fields named arrays (u_g, grad_p, T_g, rho_g, mu_g, kappa_g, cp_g, Y_g; sizes in
 * doubles) of step `step` to D and receives the sources. */
coredem_status coredem_client_exchange(coredem_client* c, int64_t step, double dt, int32_t n_fields,
                                       const char* const* names, const double* const* values,
                                       const size_t* sizes);
/* Decomposed: this rank's partial GasFields: `cells` (n_cells coupling cells its mesh touches,
 * ascending), `fluid_volume` (m3 per listed cell) and every gas field as volume-weighted sums,
 * n_cells rows each; the sources (coredem_client_source) then have n_cells rows. */
coredem_status coredem_client_exchange_partial(coredem_client* c, int64_t step, double dt,
                                               int64_t n_cells, const int64_t* cells,
                                               const double* fluid_volume, int32_t n_fields,
                                               const char* const* names,
                                               const double* const* values, const size_t* sizes);
/* View of a source array of the last exchange (eps_g, K_sl, K_sl_Us, H, H_Tp, R_species,
 * Q_hom); *size in doubles. */
coredem_status coredem_client_source(const coredem_client* c, const char* name,
                                     const double** values, size_t* size);
/* Q_rad of the last exchange: the radiation heat the particles gave the gas, W/m3 of coupling
 * cell, one value per cell (positive = heat to the gas). *values NULL and *size 0 when the DEM
 * server did not send it (protocol below 1.3). */
coredem_status coredem_client_radiation_heat(const coredem_client* c, const double** values,
                                             size_t* size);
/* mom_p of the last exchange: the momentum of the mass the particles gave the gas, N/m3 of
 * coupling cell, 3 values per cell (x, y, z). *values NULL and *size 0 when the DEM server did not
 * send it (protocol below 1.5). */
coredem_status coredem_client_released_momentum(const coredem_client* c, const double** values,
                                                size_t* size);
/* Q_split for the next exchange (protocol 1.5): the heat the gas removed beyond what the DEM
 * booked, J/m3 of coupling cell, one value per cell (exchange_partial: per listed cell, this rank's
 * own contribution). Copied; sent once. COREDEM_ERROR_ARGUMENT when a value is not finite or the
 * DEM server agreed a protocol below 1.5. After a grant, before that step's exchange. */
coredem_status coredem_client_set_heat_to_particles(coredem_client* c, const double* values,
                                                    size_t size);

/* StepDone to O: Courant number, energy ledgers (name/value pairs, J) and the checkpoint files
 * written for this step; then waits for the next grant or Shutdown. */
coredem_status coredem_client_advance(coredem_client* c, double courant, int32_t n_ledgers,
                                      const char* const* ledger_names, const double* ledger_values,
                                      int32_t n_files, const char* const* checkpoint_files);

coredem_status coredem_client_finalize(coredem_client* c);
void coredem_client_destroy(coredem_client* c);

/* Message of the last failed call on this handle ("" if none). Never NULL. */
const char* coredem_client_last_error(const coredem_client* c);
/* "OK", "ERROR_STATE", ... */
const char* coredem_status_name(coredem_status s);

#ifdef __cplusplus
}
#endif

#endif /* COREDEM_CLIENT_H */
