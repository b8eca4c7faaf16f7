/* A C program coupling through the client's C API (coredem_client.h): it takes its peers from
 * the environment, sends uniform gas fields every granted step, reads the sources, checks their
 * sizes and bounds, and reports the solid volume Σ (1 − ε_g) V_c as a ledger so that the test
 * driver can compare it with the particle volume. Exit code 0 = every check passed. */
#include <stdio.h>
#include <stdlib.h>

#include <coredem/client/coredem_client.h>

#define CHECK(call)                                                                                \
  do {                                                                                             \
    coredem_status s_ = (call);                                                                    \
    if (s_ != COREDEM_OK) {                                                                        \
      fprintf(stderr, "c_api_test: %s failed: %s: %s\n", #call, coredem_status_name(s_),           \
              coredem_client_last_error(c));                                                       \
      return 1;                                                                                    \
    }                                                                                              \
  } while (0)

#define EXPECT(cond)                                                                               \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      fprintf(stderr, "c_api_test: expectation failed: %s\n", #cond);                              \
      return 1;                                                                                    \
    }                                                                                              \
  } while (0)

int main(void) {
  coredem_client* c = NULL;
  CHECK(coredem_client_create(NULL, NULL, NULL, &c));
  /* Calls out of order are refused with ERROR_STATE and a message. */
  EXPECT(coredem_client_advance(c, 0.1, 0, NULL, NULL, 0, NULL) == COREDEM_ERROR_STATE);
  EXPECT(coredem_client_last_error(c)[0] != '\0');
  EXPECT(coredem_client_state(c) == COREDEM_STATE_CREATED);
  CHECK(coredem_client_set_timeout(c, 20.0));
  CHECK(coredem_client_initialize(c));

  coredem_grid g;
  CHECK(coredem_client_grid(c, &g));
  const size_t n = (size_t)g.cell_count;
  const size_t ns = (size_t)g.species_count;
  const double vc = g.spacing[0] * g.spacing[1] * g.spacing[2];
  double* u = calloc(3 * n, sizeof(double));
  double* gp = calloc(3 * n, sizeof(double));
  double* scal[5];
  const double values[5] = {300.0, 1.2, 1.8e-5, 0.026, 1005.0}; /* T_g rho_g mu_g kappa_g cp_g */
  double* y = calloc(n * ns + 1, sizeof(double));
  for (int f = 0; f < 5; ++f) {
    scal[f] = malloc(n * sizeof(double));
    for (size_t i = 0; i < n; ++i)
      scal[f][i] = values[f];
  }
  for (size_t i = 0; i < n; ++i) {
    u[3 * i + 2] = 0.2;
    if (ns > 0)
      y[i * ns] = 1.0;
  }
  const char* names[8] = {"u_g", "grad_p", "T_g", "rho_g", "mu_g", "kappa_g", "cp_g", "Y_g"};
  const double* ptrs[8] = {u, gp, scal[0], scal[1], scal[2], scal[3], scal[4], y};
  const size_t sizes[8] = {3 * n, 3 * n, n, n, n, n, n, n * ns};

  int steps = 0;
  while (coredem_client_is_running(c)) {
    coredem_grant gr;
    CHECK(coredem_client_grant(c, &gr));
    EXPECT(gr.dt > 0.0 && gr.n_sub >= 1);
    const double* eps = NULL;
    size_t len = 0;
    EXPECT(coredem_client_source(c, "eps_g", &eps, &len) == COREDEM_ERROR_STATE);
    /* A wrong size is refused before anything is sent, and the state stays Granted. */
    const size_t bad[8] = {3 * n - 1, 3 * n, n, n, n, n, n, n * ns};
    EXPECT(coredem_client_exchange(c, gr.step, gr.dt, 8, names, ptrs, bad) ==
           COREDEM_ERROR_ARGUMENT);
    EXPECT(coredem_client_state(c) == COREDEM_STATE_GRANTED);
    CHECK(coredem_client_exchange(c, gr.step, gr.dt, 8, names, ptrs, sizes));
    CHECK(coredem_client_source(c, "eps_g", &eps, &len));
    EXPECT(len == n);
    double solid = 0.0;
    for (size_t i = 0; i < n; ++i) {
      EXPECT(eps[i] >= 0.0 && eps[i] <= 1.0);
      solid += (1.0 - eps[i]) * vc;
    }
    const double* r = NULL;
    CHECK(coredem_client_source(c, "R_species", &r, &len));
    EXPECT(len == n * ns);
    /* Protocol 1.3: Q_rad, one value per cell (this client and the server speak 1.3), finite. */
    const double* qrad = NULL;
    CHECK(coredem_client_radiation_heat(c, &qrad, &len));
    EXPECT(len == n && qrad != NULL);
    for (size_t i = 0; i < len; ++i)
      EXPECT(qrad[i] == qrad[i]);
    EXPECT(coredem_client_radiation_heat(c, NULL, &len) == COREDEM_ERROR_ARGUMENT);
    const char* lname[1] = {"c_api.solid_volume_m3"};
    CHECK(coredem_client_advance(c, 0.0, 1, lname, &solid, 0, NULL));
    ++steps;
  }
  EXPECT(coredem_client_state(c) == COREDEM_STATE_FINISHED);
  CHECK(coredem_client_finalize(c));
  coredem_client_destroy(c);
  for (int f = 0; f < 5; ++f)
    free(scal[f]);
  free(u);
  free(gp);
  free(y);
  printf("c_api_test: %d steps\n", steps);
  return steps > 0 ? 0 : 1;
}
