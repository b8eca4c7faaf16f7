#!/usr/bin/python3
"""Reference values of the thermochemistry unit tests, computed independently of the C++ kernels.

Writes thermochem_reference.h, the tables the tests in tests/unit/thermochem compare with:

  * NASA-7 (docs/physics.md §3.5, Appendix A): H, C_p, S of the nine species from the Burcat
    (MFiX copy) coefficients transcribed below, reaction enthalpies of R1-R5, the WGS
    equilibrium constant from ΔG = ΔH - T ΔS and the seed's exp(-4.33 + 4577.8/T).
  * Contact conduction (§3.2, §8.1): intersection radius, exchange coefficients a, b, the
    two-particle analytic solution, for the MFiX-CC case and the seed's variants.
  * Gas-lens conduction (§3.3, §8.2): the lens integral I of Eq. 24 by tanh-sinh quadrature
    (mpmath) at 50 digits, with the clipped part (gap < s_min) in closed form; the MFiX-PFP
    case, the seed's gap/overlap variants and a table over the DEM range at the binary (double)
    inputs the tests pass (R_lens = (1.0 + 0.2) R_L rounded to double as the kernel does).
  * Radiation (§3.4, §8.4): the constants of the MFiX case and a classical RK4 of the two
    particles (Python floats, Δt = 1e-3 s) for both environment-temperature variants.
  * Convection (§3.1, §8.3): Ranz-Marshall for the MFiX-CONV case.
  * The verification suite (§8.0, §8.1, §8.2, §8.5): masses, heat capacities, analytic
    temperatures, the MFiX reaction case.

Only the Python standard library and mpmath (Debian: python3-mpmath). Usage:
    /usr/bin/python3 make_thermochem_reference.py > thermochem_reference.h
    /usr/bin/python3 make_thermochem_reference.py --check thermochem_reference.h
(--check regenerates and compares with the committed header; the ctest thermochem.reference_values
runs it.)
"""
import math
import sys

import mpmath
from mpmath import mp, mpf

mp.dps = 50

R_GAS = mpf("8.314462618")  # J/(mol K), CODATA 2018 (exact)
SIGMA = mpf("5.670374419e-8")  # W/(m² K⁴), CODATA 2018
PI = mp.pi

# ---- NASA-7 -------------------------------------------------------------------------------------
# Burcat's thermodynamic database as copied by MFiX (BURCAT.THR): per species the temperature
# intervals [t_min, t_max) and the seven coefficients a1..a7 of each:
#   C_p/R = a1 + a2 T + a3 T² + a4 T³ + a5 T⁴
#   H/R   = a1 T + a2 T²/2 + a3 T³/3 + a4 T⁴/4 + a5 T⁵/5 + a6
#   S/R   = a1 ln T + a2 T + a3 T²/2 + a4 T³/3 + a5 T⁴/4 + a7
_GAS_LOW_HIGH = {
    "CO": ((200, 1000, "3.5795335 -6.1035369E-04 1.0168143E-06 9.0700586E-10 -9.0442449E-13 "
                       "-1.4344086E+04 3.5084093"),
           (1000, 6000, "3.0484859 1.3517281E-03 -4.8579405E-07 7.8853644E-11 -4.6980746E-15 "
                        "-1.4266117E+04 6.0170977")),
    "CO2": ((200, 1000, "2.3568130 8.9841299E-03 -7.1220632E-06 2.4573008E-09 -1.4288548E-13 "
                        "-4.8371971E+04 9.9009035"),
            (1000, 6000, "4.6365111 2.7414569E-03 -9.9589759E-07 1.6038666E-10 -9.1619857E-15 "
                         "-4.9024904E+04 -1.9348955")),
    "H2": ((200, 1000, "2.34433112 7.98052075E-03 -1.94781510E-05 2.01572094E-08 -7.37611761E-12 "
                       "-9.17935173E+02 6.83010238E-01"),
           (1000, 6000, "2.93286575 8.26608026E-04 -1.46402364E-07 1.54100414E-11 -6.88804800E-16 "
                        "-8.13065581E+02 -1.02432865")),
    "H2O": ((200, 1000, "4.1986352 -2.0364017E-03 6.5203416E-06 -5.4879269E-09 1.7719680E-12 "
                        "-3.0293726E+04 -8.4900901E-01"),
            (1000, 6000, "2.6770389 2.9731816E-03 -7.7376889E-07 9.4433514E-11 -4.2689991E-15 "
                         "-2.9885894E+04 6.8825500")),
    "N2": ((200, 1000, "3.53100528 -1.23660988E-04 -5.02999433E-07 2.43530612E-09 -1.40881235E-12 "
                       "-1.04697628E+03 2.96747038"),
           (1000, 6000, "2.95257637 1.39690040E-03 -4.92631603E-07 7.86010195E-11 -4.60755204E-15 "
                        "-9.23948688E+02 5.87188762")),
    "C": ((200, 1000, "-3.03744539E-01 4.36036227E-03 1.98268825E-06 -6.43472598E-09 "
                      "2.99601320E-12 -1.09458288E+02 1.08301475"),
          (1000, 6000, "1.59828070 1.43065097E-03 -5.09435105E-07 8.64401302E-11 -5.34349530E-15 "
                       "-7.45940284E+02 -9.30332005")),
}
_SOLIDS = {
    "Fe2O3": ((mpf("298.15"), 960, "0.152218166 6.70757040E-02 -1.12860954E-04 9.93356662E-08 "
                                   "-3.27580975E-11 -1.01344092E+05 -6.15024507"),
              (960, 1000, "17.2604275 -1.25903995E-04 0 0 0 -1.04248826E+05 -88.6853598"),
              (1000, 1800, "16.5731962 1.72136540E-03 -1.92396010E-06 9.30825106E-10 "
                           "-1.66903100E-13 -1.04043235E+05 -85.0919728")),
    "Fe3O4": ((mpf("298.15"), 850, "4.84450959 4.39051578E-02 5.24676763E-05 -2.20801809E-07 "
                                   "1.74856371E-10 -1.38015344E+05 -23.8418082"),
              (850, 1000, "80.1656571 -9.93203597E-02 4.41610956E-05 0 0 -1.61839980E+05 "
                          "-429.480191"),
              (1000, 1870, "84.2362953 -1.35489942E-01 1.09817004E-04 -3.87847180E-08 "
                           "5.22775385E-12 -1.61060501E+05 -442.636234")),
    "Al2O3": ((200, 1000, "-8.37648940 1.09323686E-01 -2.25731157E-04 2.29482917E-07 "
                          "-9.22595951E-11 -2.02316511E+05 29.4431298"),
              (1000, 1200, "2.60994032 3.76023553E-02 -4.63474789E-05 2.73301680E-08 "
                           "-6.21672705E-12 -2.03702845E+05 -18.3258490"),
              (1200, 2327, "12.2306950 3.61303142E-03 -1.36449202E-06 5.02558143E-10 "
                           "-6.84618788E-14 -2.05837976E+05 -65.8728585")),
}
SPECIES = {}
for _name, _ivs in list(_GAS_LOW_HIGH.items()) + list(_SOLIDS.items()):
    SPECIES[_name] = [(mpf(lo), mpf(hi), [mpf(x) for x in text.split()]) for lo, hi, text in _ivs]


def nasa_coefficients(species, t):
    """The interval holding t: below the first break the first set, the last set beyond the end."""
    ivs = SPECIES[species]
    for lo, hi, a in ivs[:-1]:
        if t < hi:
            return a
    return ivs[-1][2]


def enthalpy(species, t):
    a = nasa_coefficients(species, t)
    return R_GAS * (a[0] * t + a[1] * t**2 / 2 + a[2] * t**3 / 3 + a[3] * t**4 / 4 +
                    a[4] * t**5 / 5 + a[5])


def heat_capacity(species, t):
    a = nasa_coefficients(species, t)
    return R_GAS * (a[0] + a[1] * t + a[2] * t**2 + a[3] * t**3 + a[4] * t**4)


def entropy(species, t):
    a = nasa_coefficients(species, t)
    return R_GAS * (a[0] * mpmath.log(t) + a[1] * t + a[2] * t**2 / 2 + a[3] * t**3 / 3 +
                    a[4] * t**4 / 4 + a[6])


# The CLG reactions (docs/physics.md §3.5), in the order of ClgReaction R1..R5.
REACTIONS = [
    {"C": -1, "CO2": -1, "CO": 2},                  # R1 C + CO2 -> 2 CO
    {"C": -1, "H2O": -1, "CO": 1, "H2": 1},         # R2 C + H2O -> CO + H2
    {"CO": -1, "H2O": -1, "CO2": 1, "H2": 1},       # R3 CO + H2O -> CO2 + H2 (WGS)
    {"Fe2O3": -3, "CO": -1, "Fe3O4": 2, "CO2": 1},  # R4
    {"Fe2O3": -3, "H2": -1, "Fe3O4": 2, "H2O": 1},  # R5
]


def reaction_enthalpy(nu, t):
    return sum(n * enthalpy(s, t) for s, n in nu.items())


def equilibrium_constant(nu, t):
    """K = exp(-ΔG°/(R T)) with ΔG° = Σ ν (H - T S) (Δn = 0 for the WGS: no pressure term)."""
    dg = sum(n * (enthalpy(s, t) - t * entropy(s, t)) for s, n in nu.items())
    return mpmath.exp(-dg / (R_GAS * t))


# ---- verification materials (docs/physics.md §8.0: Musser 2011 / MFiX dem-tests, CGS -> SI) -----
CAL_CM = mpf("418.4")  # cal/(s cm K) -> W/(m K)
CAL_G = mpf("4184")    # cal/(g K) -> J/(kg K)
MAT_A = dict(rho=mpf(420), k=mpf("0.131453") * CAL_CM, cp=mpf("0.191204") * CAL_G, em=mpf("0.8"))
MAT_B = dict(rho=mpf(8850), k=mpf("0.002008") * CAL_CM, cp=mpf("0.013145") * CAL_G, em=mpf("0.8"))
LENS_GAS_K = mpf("1.239e-4") * CAL_CM


def sphere_mass(mat, d):
    return mat["rho"] * PI / 6 * d**3


def heat_capacity_of(mat, d):
    return sphere_mass(mat, d) * mat["cp"]


def chord(ra, rb, l):
    """Radius of the circle where spheres of radii ra, rb at distance l intersect (0: none)."""
    x = (ra * ra - rb * rb + l * l) / (2 * l)
    return mpmath.sqrt(ra * ra - x * x) if x < ra else mpf(0)


def exchange(a, b, t10, t20, t):
    """Two lumped particles coupled by dT1/dt = a (T2 - T1), dT2/dt = b (T1 - T2)."""
    e = mpmath.exp(-(a + b) * t)
    base = b * t10 + a * t20
    return (base + a * (t10 - t20) * e) / (a + b), (base - b * (t10 - t20) * e) / (a + b)


def contact_coefficients(d1, m1, d2, m2, l):
    """Eq. 22-23: H = 4 k1 k2/(k1 + k2) r_c; a = H/(m1 c1), b = H/(m2 c2)."""
    rc = chord(max(d1, d2) / 2, min(d1, d2) / 2, l)
    h = 4 * m1["k"] * m2["k"] / (m1["k"] + m2["k"]) * rc
    return rc, h / heat_capacity_of(m1, d1), h / heat_capacity_of(m2, d2)


# ---- gas lens -----------------------------------------------------------------------------------
def lens_integral(big, small, l, s_min, r_lens):
    """I = ∫_{R_in}^{R_out} 2π r dr / max(gap(r), s_min) (Eq. 24-26 with the [C] R_out = R_S
    rule), all arguments mpf. The gap increases with r; where it is below s_min (from R_in up to
    r*) the integrand is 2π r/s_min, integrated exactly; the rest by tanh-sinh on panels graded
    towards r* (where the integrand is steepest)."""
    if not l < r_lens + small:
        return mpf(0)
    r_out = small if l * l <= r_lens**2 - small**2 else chord(r_lens, small, l)
    r_in = chord(big, small, l) if l < big + small else mpf(0)

    def gap(r):
        return l - mpmath.sqrt(big**2 - r**2) - mpmath.sqrt(small**2 - r**2)

    if gap(r_in) >= s_min:
        r_star = r_in
    elif gap(r_out) <= s_min:
        r_star = r_out
    else:
        # gap(r) = s: √(B - u) + √(S - u) = c := l - s with u = r²; their difference is
        # (B - S)/c, so √(B - u) = (c² + B - S)/(2c) and u = B - ((c² + B - S)/(2c))².
        c = l - s_min
        u = big**2 - ((c * c + big**2 - small**2) / (2 * c))**2
        r_star = mpmath.sqrt(u)
    total = PI * (r_star**2 - r_in**2) / s_min
    if r_out > r_star:
        span = r_out - r_star
        points = [r_star] + [r_star + span * mpf(10)**(-k) for k in range(14, 0, -1)] + [r_out]
        total += mpmath.quad(lambda r: 2 * PI * r / gap(r), points)
    return total


def lens_integral_of_doubles(big, small, l, s_min, lens_fraction=0.2):
    """The integral at the binary inputs of a test: every argument a Python float, R_lens
    rounded to double as the kernel computes it."""
    r_lens = (1.0 + lens_fraction) * big
    return lens_integral(mpf(big), mpf(small), mpf(l), mpf(s_min), mpf(r_lens))


def lens_coefficients(d1, m1, d2, m2, l, kg, s_min):
    big, small = max(d1, d2) / 2, min(d1, d2) / 2
    i = lens_integral(big, small, l, s_min, (1 + mpf("0.2")) * big)
    return i, kg * i / heat_capacity_of(m1, d1), kg * i / heat_capacity_of(m2, d2)


# ---- output -------------------------------------------------------------------------------------
def num(x, digits=17):
    """A C++ double literal: 17 significant digits round-trip any double."""
    s = mpmath.nstr(mpf(x), digits, min_fixed=-4, max_fixed=5, strip_zeros=False)
    if "e" not in s and "." not in s:
        s += ".0"
    return s.replace("e+", "e")


def lit(x):
    """A Python float input as the shortest literal that reads back to the same double."""
    return repr(float(x))


class Header:
    def __init__(self):
        self.lines = []

    def comment(self, text):
        for line in text.strip().split("\n"):
            self.lines.append("// " + line if line else "//")

    def const(self, name, value, digits=17):
        self.lines.append("inline constexpr double %s = %s;" % (name, num(value, digits)))

    def table(self, struct, fields, name, rows):
        self.lines.append("struct %s {" % struct)
        self.lines.append("  double %s;" % ", ".join(fields))
        self.lines.append("};")
        self.lines.append("inline constexpr %s %s[] = {" % (struct, name))
        for r in rows:
            self.lines.append("    {%s}," % ", ".join(r))
        self.lines.append("};")

    def blank(self):
        self.lines.append("")


def nasa7_section(h):
    h.comment("NASA-7 (Burcat/MFiX coefficients): H (J/mol), C_p and S (J/(mol K)) at T (K).")
    h.lines.append("struct Nasa7Point {")
    h.lines.append("  Species species;")
    h.lines.append("  double t, h, cp, s;")
    h.lines.append("};")
    h.lines.append("inline constexpr Nasa7Point kNasa7[] = {")
    points = [("CO", "300.0"), ("CO", "1173.15"), ("CO2", "500.0"), ("CO2", "1500.0"),
              ("H2", "300.0"), ("H2", "1173.15"), ("H2O", "500.0"), ("H2O", "1500.0"),
              ("N2", "300.0"), ("N2", "1173.15"), ("C", "500.0"), ("C", "1500.0"),
              ("Fe2O3", "300.0"), ("Fe2O3", "1173.15"), ("Fe3O4", "500.0"), ("Fe3O4", "1500.0"),
              ("Al2O3", "300.0"), ("Al2O3", "1173.15"), ("Al2O3", "1500.0")]
    for s, t in points:
        tt = mpf(t)
        h.lines.append("    {Species::%s, %s, %s, %s, %s}," %
                       (s, t, num(enthalpy(s, tt)), num(heat_capacity(s, tt)),
                        num(entropy(s, tt))))
    h.lines.append("};")
    h.blank()
    h.comment("Reaction enthalpies ΔH_r = Σ ν H (J/mol) of R1..R5 at T (K).")
    rows = []
    for t in ("298.15", "1073.15", "1173.15", "1223.15"):
        rows.append([t] + [num(reaction_enthalpy(nu, mpf(t))) for nu in REACTIONS])
    h.table("ReactionEnthalpyRow", ["t", "r1, r2, r3, r4, r5"], "kReactionEnthalpy", rows)
    h.blank()
    h.comment("WGS equilibrium constant: thermodynamic exp(-ΔG/(R T)), and the seed's\n"
              "exp(-4.33 + 4577.8/T), at 1000 K and 1173.15 K.")
    h.const("kWgsThermo1000", equilibrium_constant(REACTIONS[2], mpf(1000)))
    h.const("kWgsThermo1173", equilibrium_constant(REACTIONS[2], mpf("1173.15")))
    h.const("kWgsSeed1000", mpmath.exp(mpf("-4.33") + mpf("4577.8") / 1000))
    h.blank()


def conduction_section(h):
    l_cc = (mpf("0.4799731") - mpf("0.1499864")) * mpf("1e-2")
    rc, a, b = contact_coefficients(mpf("3.0e-3"), MAT_A, mpf("3.6e-3"), MAT_B, l_cc)
    h.comment("MFiX-CC (§8.1): d_A = 3.0 mm (material A), d_B = 3.6 mm (B), l from the file's\n"
              "positions (0.4799731 - 0.1499864) cm: r_c (m), a = H/(m_A c_A), b = H/(m_B c_B) (1/s).")
    h.const("kMfixCcContactRadius", rc)
    h.const("kMfixCcA", a)
    h.const("kMfixCcB", b)
    t1, t2 = exchange(a, b, mpf("298.15"), mpf("453.15"), mpf("9.901"))
    h.const("kMfixCcT1At9901ms", t1)
    t1, t2 = exchange(a, b, mpf("298.15"), mpf("453.15"), mpf("49.901"))
    h.const("kMfixCcT1At49901ms", t1)
    h.const("kMfixCcT2At49901ms", t2)
    h.const("kMfixCcEquilibrium", (b * mpf("298.15") + a * mpf("453.15")) / (a + b))
    h.blank()
    h.comment("Seed contact-conduction variants (§8.1): particle 1 = A, 3.0 mm at 373.15 K; particle\n"
              "2 = B, d2 at 278.15 K; overlap ov (m), l = 1.5 mm + d2/2 - ov. r_c (m), a, b (1/s),\n"
              "T_inf and T1, T2 after 10 s (K).")
    rows = []
    for d2, ov in (("2.4e-3", "1e-5"), ("2.4e-3", "4e-5"), ("3.0e-3", "1e-5"), ("3.0e-3", "4e-5"),
                   ("3.6e-3", "1e-5"), ("3.6e-3", "2e-5"), ("3.6e-3", "3e-5"), ("3.6e-3", "4e-5")):
        dd, oo = mpf(d2), mpf(ov)
        rc, a, b = contact_coefficients(mpf("3.0e-3"), MAT_A, dd, MAT_B, mpf("1.5e-3") + dd / 2 - oo)
        t1, t2 = exchange(a, b, mpf("373.15"), mpf("278.15"), mpf(10))
        tinf = (b * mpf("373.15") + a * mpf("278.15")) / (a + b)
        rows.append([d2, ov, num(rc), num(a), num(b), num(tinf), num(t1), num(t2)])
    h.table("SeedContactRow", ["d2, ov, rc, a, b, tInf, t1, t2"], "kSeedContact", rows)
    h.blank()

    l_pfp = (mpf("1.498") - mpf("1.150")) * mpf("1e-2")
    big, small = mpf("1.8e-3"), mpf("1.5e-3")
    r_lens = mpf("1.2") * big
    h.comment("MFiX-PFP (§8.2): no contact, l = (1.498 - 1.150) cm, s_min = 1e-6 m, κ_g = 1.239e-4\n"
              "cal/(s cm K): R_out (m), I (m), a, b (1/s), T_A and T_B after 49.9 s (K).")
    h.const("kMfixPfpOuterRadius", chord(r_lens, small, l_pfp))
    i, a, b = lens_coefficients(mpf("3.0e-3"), MAT_A, mpf("3.6e-3"), MAT_B, l_pfp, LENS_GAS_K,
                                mpf("1e-6"))
    h.const("kMfixPfpIntegral", i)
    h.const("kMfixPfpA", a)
    h.const("kMfixPfpB", b)
    t1, t2 = exchange(a, b, mpf("298.15"), mpf("453.15"), mpf("49.9"))
    h.const("kMfixPfpT1At49900ms", t1)
    h.const("kMfixPfpT2At49900ms", t2)
    h.blank()
    h.comment("Seed lens variants (§8.2): the 3.0 mm A and 3.6 mm B spheres at surface gap `gap` (m,\n"
              "negative: overlap) with s_min (m): I (m), a, b (1/s), T1 after 10 s from 373.15/278.15 K.")
    rows = []
    for gap, smin in (("1e-5", "1e-6"), ("2e-5", "1e-6"), ("1.8e-4", "1e-6"), ("-1e-5", "1e-6"),
                      ("-1e-5", "4e-10"), ("-4e-5", "1e-6"), ("-4e-5", "4e-10")):
        l = mpf("3.3e-3") + mpf(gap)
        i, a, b = lens_coefficients(mpf("3.0e-3"), MAT_A, mpf("3.6e-3"), MAT_B, l, LENS_GAS_K,
                                    mpf(smin))
        t1, _ = exchange(a, b, mpf("373.15"), mpf("278.15"), mpf(10))
        rows.append([gap, smin, num(i), num(a), num(b), num(t1)])
    h.table("SeedLensRow", ["gap, sMin, integral, a, b, t1At10s"], "kSeedLens", rows)
    h.blank()
    h.comment("The lens integral I (m) at binary inputs over the DEM range (R_L, R_S, l, s_min in m,\n"
              "as doubles; R_lens = (1.0 + 0.2) R_L rounded to double), 20 significant digits; the\n"
              "last four 1e-6 below the lens reach. The first six have equal radii.")
    cases = [
        (0.001, 0.001, 0.0019500000000000001, 1e-10), (0.001, 0.001, 0.001999999, 1e-06),
        (0.001, 0.001, 0.0020003, 1e-06), (0.001, 0.001, 0.0021, 1e-08),
        (0.001, 0.001, 0.002199998, 1e-06), (0.01, 0.01, 0.021999998, 1e-06),
        (0.01, 0.001, 0.01095, 1e-05), (0.01, 0.001, 0.010999, 1e-10),
        (0.01, 0.001, 0.011002, 1e-09), (0.01, 0.001, 0.012499999999999999, 1e-06),
        (0.0001, 1e-05, 0.0001095, 1e-10), (0.0001, 1.5e-05, 0.000134, 1e-07),
        (0.0001, 5e-05, 0.00014800000000000002, 1e-05), (0.0001, 9.9e-05, 0.000203, 1e-05),
        (0.002, 0.0012, 0.0031699999999999996, 4e-10), (0.005, 0.004, 0.009800000000000001, 1e-07),
        (0.0018, 0.0015, 0.00331, 1e-06), (0.001, 0.0002, 0.00119, 1e-08),
        (0.001, 0.0003, 0.0014998, 1e-09), (0.001, 0.0001, 0.0012900000000000001, 1e-10),
        (0.001, 0.00015, 0.001148, 1e-06),
        (0.0001, 1.8e-05, 0.00013799998000000002, 1e-06), (0.0001, 5e-05, 0.00016999998, 1e-06),
        (0.001, 0.0001, 0.0012999998, 1e-06),
    ]
    rows = []
    for big, small, l, smin in cases:
        rows.append([lit(big), lit(small), lit(l), lit(smin),
                     num(lens_integral_of_doubles(big, small, l, smin), 20)])
    h.table("LensIntegralRow", ["big, small, l, sMin, integral"], "kLensIntegral", rows)
    h.blank()


def radiation_section(h):
    d1, d2 = 3.0e-3, 3.6e-3
    eps = 1 - math.pi / 6 * (d1**3 + d2**3) / (0.015 * 0.01 * 0.0036)
    c1 = MAT_A["em"] * SIGMA * PI * mpf(d1)**2 / heat_capacity_of(MAT_A, mpf(d1))
    c2 = MAT_B["em"] * SIGMA * PI * mpf(d2)**2 / heat_capacity_of(MAT_B, mpf(d2))
    h.comment("MFiX radiation case (§8.4): ε_g of the 1.5 x 1.0 x 0.36 cm cell holding both spheres,\n"
              "C = e σ π d²/(m c) (1/(s K³)) of A (3.0 mm) and B (3.6 mm).")
    eps_exact = 1 - PI / 6 * (mpf(d1)**3 + mpf(d2)**3) / (mpf("0.015") * mpf("0.01") * mpf("0.0036"))
    h.const("kRadiationVoidage", eps_exact)
    h.const("kRadiationCA", c1)
    h.const("kRadiationCB", c2)
    cf1, cf2, tg = float(c1), float(c2), 400.0

    def rk4(neighbours, marks, dt=1e-3):
        t1, t2 = 298.15, 453.15

        def rate(x1, x2):
            if neighbours:  # T_env,i = ε T_g + (1 - ε) T_j
                e1, e2 = eps * tg + (1 - eps) * x2, eps * tg + (1 - eps) * x1
            else:  # the cell mean including the particle itself
                e1 = e2 = eps * tg + (1 - eps) * 0.5 * (x1 + x2)
            return cf1 * (e1**4 - x1**4), cf2 * (e2**4 - x2**4)

        out, step, n = [], 0, 0
        for mark in marks:
            n = int(round(mark / dt))
            while step < n:
                k1 = rate(t1, t2)
                k2 = rate(t1 + 0.5 * dt * k1[0], t2 + 0.5 * dt * k1[1])
                k3 = rate(t1 + 0.5 * dt * k2[0], t2 + 0.5 * dt * k2[1])
                k4 = rate(t1 + dt * k3[0], t2 + dt * k3[1])
                t1 += dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
                t2 += dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
                step += 1
            out.append((t1, t2))
        return out

    marks = [10.0, 50.0, 100.0, 200.0, 300.0]
    h.comment("Classical RK4, Δt = 1e-3 s, T_A0 = 298.15 K, T_B0 = 453.15 K, T_g = 400 K (Python\n"
              "floats): T_A, T_B (K) at t (s) with the cell-mean environment (MFiX) and with the\n"
              "neighbour-only one.")
    rows = [[lit(t), repr(a), repr(b)] for t, (a, b) in zip(marks, rk4(False, marks))]
    h.table("RadiationRow", ["t, t1, t2"], "kRadiationCellMean", rows)
    rows = [[lit(t), repr(a), repr(b)] for t, (a, b) in zip(marks, rk4(True, marks))]
    h.lines.append("inline constexpr RadiationRow kRadiationNeighbours[] = {")
    for r in rows:
        h.lines.append("    {%s}," % ", ".join(r))
    h.lines.append("};")
    h.blank()


def convection_section(h):
    d, u = mpf("3.6e-3"), mpf(6)
    rho, mu = mpf("1.1854"), mpf("1.8603e-5")
    k, cp = mpf("1.2396e-4") * CAL_CM, mpf("0.23878") * CAL_G
    re = rho * u * d / mu
    pr = mu * cp / k
    nu = 2 + mpf("0.6") * mpmath.sqrt(re) * mpmath.cbrt(pr)
    coef = nu * k / d * PI * d * d / heat_capacity_of(MAT_B, d)
    h.comment("MFiX-CONV (§8.3): a fixed 3.6 mm sphere of material B in the MFiX gas at 6 m/s,\n"
              "Ranz-Marshall with Re = ρ u d/μ (no voidage): Re, Pr, Nu and h A/(m c) (1/s); the\n"
              "particle temperature from 373.15 K in gas at 298.15 K after 1 s and 5 s (K).")
    h.const("kConvectionReynolds", re)
    h.const("kConvectionPrandtl", pr)
    h.const("kConvectionNusselt", nu)
    h.const("kConvectionCoefficient", coef)
    for t in (1, 5):
        h.const("kConvectionTAt%ds" % t,
                mpf("298.15") - (mpf("298.15") - mpf("373.15")) * mpmath.exp(-coef * t))
    h.const("kConvectionCellVoidage",
            1 - PI / 6 * d**3 / (mpf("0.04") * mpf("0.04") * mpf("0.0036")))
    h.blank()


def verification_section(h):
    h.comment("§8.0 property set: masses (kg) and heat capacities m c (J/K) of the 3.0 mm A and\n"
              "3.6 mm B spheres, their conductivities and the lens gas's (W/(m K)).")
    h.const("kMassA", sphere_mass(MAT_A, mpf("3.0e-3")))
    h.const("kMassB", sphere_mass(MAT_B, mpf("3.6e-3")))
    h.const("kHeatCapacityA", heat_capacity_of(MAT_A, mpf("3.0e-3")))
    h.const("kHeatCapacityB", heat_capacity_of(MAT_B, mpf("3.6e-3")))
    h.const("kConductivityA", MAT_A["k"])
    h.const("kConductivityB", MAT_B["k"])
    h.const("kLensGasConductivity", LENS_GAS_K)
    h.blank()
    # §8.5: a 3 mm sphere (ρ = 2500) of B (0.5) and inert I (0.5); B + ... -> D at ω mol/s with
    # 2 mol of B (15 g/mol) consumed and 1 mol of D (25 g/mol) made per reaction.
    m0 = mpf(2500) * PI / 6 * mpf("3e-3")**3
    omega = mpf("3.927e-4")
    r_b = 2 * mpf("15e-3") * omega
    r_d = mpf("25e-3") * omega
    t_end = m0 * mpf("0.5") / r_b
    h.comment("MFiX reaction case (§8.5): a 3 mm sphere (ρ = 2500 kg/m³) half B, half inert; ω =\n"
              "3.927e-4 mol/s consumes 2 B (15 g/mol) and makes 1 D (25 g/mol) until B is gone:\n"
              "m0 (kg), t_end (s), and m (kg), X_B, X_D, X_I at t (s).")
    h.const("kReactionMass0", m0)
    h.const("kReactionEndTime", t_end)
    rows = []
    for t in ("0.0", "0.5", "1.0", "1.5", "2.0"):
        tc = min(mpf(t), t_end)
        m = m0 + (r_d - r_b) * tc
        rows.append([t, num(m), num((m0 / 2 - r_b * tc) / m), num(r_d * tc / m), num(m0 / 2 / m)])
    h.table("ReactionRow", ["t, m, xB, xD, xI"], "kReaction", rows)
    h.blank()


def generate():
    h = Header()
    h.lines.append("// Generated by make_thermochem_reference.py (same folder); do not edit: run")
    h.lines.append("//   /usr/bin/python3 make_thermochem_reference.py > thermochem_reference.h")
    h.lines.append("// The ctest thermochem.reference_values checks that the committed file is what the")
    h.lines.append("// script makes.")
    h.lines.append("#pragma once")
    h.blank()
    h.lines.append("#include <coredem/dem/kernels/nasa7.h>")
    h.blank()
    h.lines.append("// clang-format off")
    h.lines.append("namespace coredem::test::thermochem_ref {")
    h.blank()
    h.lines.append("using coredem::dem::kernels::Species;")
    h.blank()
    nasa7_section(h)
    conduction_section(h)
    radiation_section(h)
    convection_section(h)
    verification_section(h)
    h.lines.append("} // namespace coredem::test::thermochem_ref")
    h.lines.append("// clang-format on")
    return "\n".join(h.lines) + "\n"


def main():
    text = generate()
    if len(sys.argv) == 3 and sys.argv[1] == "--check":
        with open(sys.argv[2], encoding="utf-8") as f:
            committed = f.read()
        if committed == text:
            print("thermochem reference values: %s is what the script makes" % sys.argv[2])
            return 0
        import difflib
        sys.stdout.writelines(difflib.unified_diff(committed.splitlines(True),
                                                   text.splitlines(True), "committed",
                                                   "regenerated"))
        print("thermochem reference values: %s differs from the script's output" % sys.argv[2])
        return 1
    if len(sys.argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
