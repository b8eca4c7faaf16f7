#!/usr/bin/env python3
"""Independent reference for the drag laws of docs/physics.md §2.2 (kernels/drag*.h) and the
Nusselt correlations of §3.1 that are not the seed's (kernels/nusselt_*.h).

Each law is written here as its paper (or MFiX's drag_gs.f) writes it: the interphase momentum
transfer coefficient beta (kg/m3/s) or the drag force on one particle, evaluated with mpmath at
40 digits, then turned into the per-particle coefficient beta V_p/(1 - eps) (kg/s) that the DEM's
kernels return. Writes drag_laws.yaml (drag laws, then the Nusselt correlations):
    /usr/bin/python3 make_drag_reference.py > drag_laws.yaml
"""
from mpmath import mp, mpf, sqrt, atan, exp, log10, pi

mp.dps = 40

RHO, MU = mpf("1.2"), mpf("1.8e-5")
EPS = ["0.36", "0.4", "0.45", "0.5", "0.6", "0.7", "0.79", "0.81", "0.86", "0.91", "0.95",
       "0.985", "0.999"]  # not 0.9, 0.99: Koch-Hill switches at phi = 0.1, 0.01
SLIP = ["1e-4", "0.01", "0.1", "0.5", "2", "10", "40"]
DIAM = ["1e-3", "2e-4"]


def c_d_wen_yu(re):
    return mpf("0.44") if re >= 1000 else 24 / re * (1 + mpf("0.15") * re ** mpf("0.687"))


def beta_wen_yu(e, u, d):
    re = e * RHO * d * u / MU
    return mpf(3) / 4 * c_d_wen_yu(re) * e * (1 - e) * RHO * u * e ** mpf("-2.65") / d


def beta_ergun(e, u, d):
    return 150 * (1 - e) ** 2 * MU / (e * d * d) + mpf("1.75") * (1 - e) * RHO * u / d


def beta_gidaspow(e, u, d):
    return beta_ergun(e, u, d) if e <= mpf("0.8") else beta_wen_yu(e, u, d)


def beta_blend(e, u, d):
    # MFiX DRAG_GIDASPOW_BLEND: PHI_gs weights Wen-Yu
    w = atan(mpf("262.5") * (e - mpf("0.8"))) / pi + mpf("0.5")
    return (1 - w) * beta_ergun(e, u, d) + w * beta_wen_yu(e, u, d)


def force_voidage(chi, e, u, d):
    """Drag force (N) of Di Felice's form at slip u: single sphere at the superficial slip."""
    us = e * u
    re = RHO * d * us / MU
    cd0 = (mpf("0.63") + mpf("4.8") / sqrt(re)) ** 2
    return mpf(1) / 2 * cd0 * RHO * pi * d * d / 4 * us * us * e ** (-chi)


def bell(e, u, d):
    re = e * RHO * d * u / MU
    return exp(-(mpf("1.5") - log10(re)) ** 2 / 2)


def coef_di_felice(e, u, d):
    return force_voidage(mpf("3.7") - mpf("0.65") * bell(e, u, d), e, u, d) / u


def coef_rong(e, u, d):
    chi = mpf("2.65") * (e + 1) - (mpf("5.3") - mpf("3.5") * e) * e * e * bell(e, u, d)
    return force_voidage(chi, e, u, d) / u


def beta_syamlal(e, u, d):
    re = RHO * d * u / MU
    a = e ** mpf("4.14")
    b = mpf("0.8") * e ** mpf("1.28") if e <= mpf("0.85") else e ** mpf("2.65")
    vr = (a - mpf("0.06") * re + sqrt((mpf("0.06") * re) ** 2 + mpf("0.12") * re * (2 * b - a) + a * a)) / 2
    cd = (mpf("0.63") + mpf("4.8") * sqrt(vr / re)) ** 2
    return mpf(3) / 4 * cd * e * (1 - e) * RHO * u / (vr * vr * d)


def beta_beetstra(e, u, d):
    phi = 1 - e
    re = e * RHO * d * u / MU
    f = (10 * phi / (1 - phi) ** 2 + (1 - phi) ** 2 * (1 + mpf("1.5") * sqrt(phi))
         + mpf("0.413") * re / (24 * (1 - phi) ** 2)
         * ((1 - phi) ** -1 + 3 * phi * (1 - phi) + mpf("8.4") * re ** mpf("-0.343"))
         / (1 + mpf(10) ** (3 * phi) * re ** (-(1 + 4 * phi) / 2)))
    # f_d = 3 pi mu d eps F u per particle  <=>  beta = 18 mu eps phi F / d^2
    return 18 * MU * e * phi * f / (d * d)


def beta_koch_hill(e, u, d):
    """MFiX DRAG_KOCH_HILL (Benyahia et al. 2006), written as there; the limit F_0 at Re = 0."""
    phis = 1 - e
    re = mpf("0.5") * d * u * e * RHO / MU
    f_stokes = 18 * MU * e * e / (d * d)
    w = exp(-10 * (mpf("0.4") - phis) / phis)
    from mpmath import log
    if mpf("0.01") < phis < mpf("0.4"):
        f0 = ((1 - w) * (1 + 3 * sqrt(phis / 2) + mpf(135) / 64 * phis * log(phis) + mpf("17.14") * phis)
              / (1 + mpf("0.681") * phis - mpf("8.48") * phis ** 2 + mpf("8.16") * phis ** 3)
              + w * 10 * phis / (1 - phis) ** 3)
    elif phis >= mpf("0.4"):
        f0 = 10 * phis / (1 - phis) ** 3
    if mpf("0.01") < phis <= mpf("0.1"):
        f1 = sqrt(2 / phis) / 40
    elif phis > mpf("0.1"):
        f1 = mpf("0.11") + mpf("5.1e-4") * exp(mpf("11.6") * phis)
    if phis < mpf("0.4"):
        f2 = ((1 - w) * (1 + 3 * sqrt(phis / 2) + mpf(135) / 64 * phis * log(phis) + mpf("17.89") * phis)
              / (1 + mpf("0.681") * phis - mpf("11.03") * phis ** 2 + mpf("15.41") * phis ** 3)
              + w * 10 * phis / (1 - phis) ** 3)
    else:
        f2 = 10 * phis / (1 - phis) ** 3
    f3 = mpf("0.9351") * phis + mpf("0.03667") if phis < mpf("0.0953") else \
        mpf("0.0673") + mpf("0.212") * phis + mpf("0.0232") / (1 - phis) ** 5
    re_t1 = (f2 - 1) / (mpf(3) / 8 - f3)
    if phis > mpf("0.01"):
        re_t2 = (f3 + sqrt(f3 * f3 - 4 * f1 * (f0 - f2))) / (2 * f1)
    if phis <= mpf("0.01") and re <= re_t1:
        f = 1 + mpf(3) / 8 * re
    elif phis > mpf("0.01") and re <= re_t2:
        f = f0 + f1 * re * re
    else:
        f = f2 + f3 * re
    return f * f_stokes * phis


def per_particle(beta, e, d):
    return beta * (pi * d ** 3 / 6) / (1 - e)


LAWS = {
    "gidaspow": lambda e, u, d: per_particle(beta_gidaspow(e, u, d), e, d),
    "wen-yu": lambda e, u, d: per_particle(beta_wen_yu(e, u, d), e, d),
    "ergun": lambda e, u, d: per_particle(beta_ergun(e, u, d), e, d),
    "gidaspow-blend": lambda e, u, d: per_particle(beta_blend(e, u, d), e, d),
    "di-felice": coef_di_felice,
    "rong": coef_rong,
    "syamlal-obrien": lambda e, u, d: per_particle(beta_syamlal(e, u, d), e, d),
    "beetstra": lambda e, u, d: per_particle(beta_beetstra(e, u, d), e, d),
    "koch-hill": lambda e, u, d: per_particle(beta_koch_hill(e, u, d), e, d),
}


def write_table(laws, unit):
    """One YAML list per law: [eps, slip, d_p, value] over the grid EPS x SLIP x DIAM."""
    for name, law in laws.items():
        print(f"  {name}:  # eps, slip (m/s), d_p (m), {unit}")
        for e in EPS:
            for u in SLIP:
                for d in DIAM:
                    v = law(mpf(e), mpf(u), mpf(d))
                    print(f"    - [{e}, {u}, {d}, {mp.nstr(v, 20, min_fixed=0, max_fixed=0)}]")


print("# drag_laws.yaml: per-particle drag coefficients beta V_p/(1 - eps) (kg/s) written by")
print("# make_drag_reference.py (mpmath, 40 digits) from the laws' published forms.")
print("rho_g: 1.2\nmu_g: 1.8e-5\nrelative_tolerance: 1.0e-12\nlaws:")
write_table(LAWS, "coefficient (kg/s)")

K_G, CP_G = mpf("0.026"), mpf("1006")


def gunn_form(a, c, e2):
    """Gunn's form: (7 - 10 e + 5 e^2)(1 + a Re^0.2 Pr^1/3) + (1.33 - c e + e2 e^2) Re^0.7 Pr^1/3."""
    def law(e, u, d):
        re = e * RHO * d * u / MU
        pr13 = (MU * CP_G / K_G) ** (mpf(1) / 3)
        return ((7 - 10 * e + 5 * e * e) * (1 + mpf(a) * re ** mpf("0.2") * pr13)
                + (mpf("1.33") - mpf(c) * e + mpf(e2) * e * e) * re ** mpf("0.7") * pr13)
    return law


# Gunn (1978); Deen, Peters, Padding & Kuipers (2014); Tavassoli, Peters & Kuipers (2015).
NUSSELT = {"gunn": gunn_form("0.7", "2.4", "1.2"),
           "deen": gunn_form("0.17", "2.31", "1.16"),
           "tavassoli": gunn_form("0.1", "2.19", "1.15")}


print("k_g: 0.026\ncp_g: 1006.0\nnusselt:")
write_table(NUSSELT, "Nu")
