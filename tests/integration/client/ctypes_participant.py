"""A CFD participant in Python: the client's C API through ctypes (libcoredem_client.so).

Peers come from the environment (COREDEM_CONTROL_ENDPOINT, COREDEM_DEM_ENDPOINT,
COREDEM_SESSION); COREDEM_CLIENT_LIB names the shared library. Every granted step it sends
uniform gas fields, checks the sources and reports the solid volume sum((1 - eps_g) V_c) as the
ledger "py.solid_volume_m3". Exit code 0 = every check passed.
"""
import ctypes as C
import os
import sys

import numpy as np

lib = C.CDLL(os.environ["COREDEM_CLIENT_LIB"])


class Grant(C.Structure):
    _fields_ = [("step", C.c_int64), ("time", C.c_double), ("dt", C.c_double),
                ("n_sub", C.c_int32), ("dt_dem", C.c_double),
                ("requires_checkpoint", C.c_int), ("checkpoint_dir", C.c_char_p)]


class Grid(C.Structure):
    _fields_ = [("origin", C.c_double * 3), ("spacing", C.c_double * 3),
                ("counts", C.c_int64 * 3), ("cell_count", C.c_int64),
                ("species_count", C.c_int32)]


lib.coredem_client_last_error.restype = C.c_char_p
lib.coredem_status_name.restype = C.c_char_p
handle = C.c_void_p()


def check(status, what):
    if status != 0:
        sys.exit("ctypes_participant: %s failed: %s: %s" % (
            what, lib.coredem_status_name(status).decode(),
            lib.coredem_client_last_error(handle).decode()))


check(lib.coredem_client_create(None, None, None, C.byref(handle)), "create")
check(lib.coredem_client_set_timeout(handle, C.c_double(20.0)), "set_timeout")
check(lib.coredem_client_initialize(handle), "initialize")
grid = Grid()
check(lib.coredem_client_grid(handle, C.byref(grid)), "grid")
n, ns = grid.cell_count, grid.species_count
vc = grid.spacing[0] * grid.spacing[1] * grid.spacing[2]
fields = {
    "u_g": np.tile([0.0, 0.0, 0.2], n), "grad_p": np.zeros(3 * n), "T_g": np.full(n, 300.0),
    "rho_g": np.full(n, 1.2), "mu_g": np.full(n, 1.8e-5), "kappa_g": np.full(n, 0.026),
    "cp_g": np.full(n, 1005.0), "Y_g": np.tile(np.eye(1, ns).ravel(), n) if ns else np.zeros(0),
}
names = (C.c_char_p * 8)(*[k.encode() for k in fields])
ptrs = (C.POINTER(C.c_double) * 8)(*[v.ctypes.data_as(C.POINTER(C.c_double)) for v in fields.values()])
sizes = (C.c_size_t * 8)(*[v.size for v in fields.values()])
steps = 0
while lib.coredem_client_is_running(handle):
    g = Grant()
    check(lib.coredem_client_grant(handle, C.byref(g)), "grant")
    check(lib.coredem_client_exchange(handle, C.c_int64(g.step), C.c_double(g.dt), 8, names, ptrs, sizes),
          "exchange")
    data, size = C.POINTER(C.c_double)(), C.c_size_t()
    check(lib.coredem_client_source(handle, b"eps_g", C.byref(data), C.byref(size)), "source")
    eps = np.ctypeslib.as_array(data, shape=(size.value,))
    if size.value != n or eps.min() < 0.0 or eps.max() > 1.0:
        sys.exit("ctypes_participant: bad eps_g (size %d, range %g..%g)" % (size.value, eps.min(), eps.max()))
    solid = C.c_double(float(np.sum((1.0 - eps) * vc)))
    lname = (C.c_char_p * 1)(b"py.solid_volume_m3")
    check(lib.coredem_client_advance(handle, C.c_double(0.0), 1, lname, C.byref(solid), 0, None), "advance")
    steps += 1
check(lib.coredem_client_finalize(handle), "finalize")
lib.coredem_client_destroy(handle)
print("ctypes_participant: %d steps" % steps)
sys.exit(0 if steps > 0 else 1)
