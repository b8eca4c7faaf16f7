#!/usr/bin/env python3
"""Write the fluidized bed of the DPMFoam peer comparison for both codes.

    make_case.py N SIM_SECONDS OUTDIR [--seed S] [--substep-velocity U]

writes

    OUTDIR/dpmfoam/          an OpenFOAM v1912 case for Debian's DPMFoam
    OUTDIR/coredem/case.yaml a CoReDEM case (coredemFoam + coredem-dem, cpu backend, 2 threads)
    OUTDIR/coredem/openfoam/ its OpenFOAM case folder (same mesh, same gas, same inlet)

and prints the derived parameters as `key = value` lines (README.md explains each).

Both cases: a 0.04 x 0.2 x 0.01 m column (y up) meshed 12 x 60 x 3 (3.33 mm cells, as
cases/fluidized-bed-small), N glass beads of 1 mm (2500 kg/m3), air (1.204 kg/m3,
mu 1.81e-5 Pa s) entering at the bottom with 1.2 m/s superficial velocity, laminar gas, the
same start positions (a jittered lattice computed here, seeded, written into both cases),
adaptive CFD step (Courant 0.5, at most 1 ms), Gidaspow (Ergun / Wen-Yu) drag in both.

Collisions: CoReDEM uses a linear spring-dashpot (k_n = 100 N/m, e_n = 0.9, mu = 0.1).
DPMFoam's pairSpringSliderDashpot / wallSpringSliderDashpot is Hertzian
(F_n = k_N d^1.5 - eta_N v_n with k_N = 4/3 sqrt(R) E*, eta_N = alpha sqrt(M k_N) d^0.25).
The mapping chosen here:
  * alpha from e_n: the damped Hertz contact of that form has a velocity-independent
    restitution; alpha is found by bisection on a numerical integration of one contact;
  * E* so that a contact at the reference impact velocity V_REF lasts as long as the linear
    one (t_col = pi / sqrt(k/m - eta^2/4m^2)); pair and wall separately (the wall contact of
    the linear model has m_eff = m, so it lasts sqrt(2) times longer);
  * collisionResolutionSteps so that DPMFoam's collision sub-step equals CoReDEM's
    dt_DEM = pi sqrt(m_eff/k_n)/50 when its fastest particle moves at the design speed U_SUB (default
    0.025 m/s, about the speed of the 0.01 s benchmark runs; --substep-velocity). OpenFOAM
    1912 estimates the sub-step every CFD step as
    5.429675 R (rho/(E* sqrt(U)))^0.4 / collisionResolutionSteps with, for the pair model,
    R = d_min/4 and U = 2 max(|U_p| + |omega_p| d/2) and, for the wall model, R = d_min/2 and
    U = max(|U_p| + |omega_p| d/2); it sub-cycles max(pair, wall) times. The sub-step goes
    as U^(-1/5): faster particles than U_SUB make it shorter than dt_DEM, slower ones longer
    (report.py compares DPMFoam's logged sub-cycle counts with the intended ones);
  * friction mu = 0.1 for both; DPMFoam's tangential spring is Hertz-Mindlin
    (k_T = 8 sqrt(R d) G*), CoReDEM's linear (k_t = 2/7 k_n), not matched.
"""

import argparse
import math
import os
import random
import shutil
import sys

# ---- the system (same numbers as cases/fluidized-bed-small) --------------------------------
BOX = (0.04, 0.2, 0.01)          # m, x y z; y vertical
CELLS = (12, 60, 3)
D_P = 1.0e-3                     # m
RHO_P = 2500.0                   # kg/m3
K_N = 100.0                      # N/m (CoReDEM linear spring)
E_N = 0.9
MU = 0.1
RHO_G = 1.204                    # kg/m3
MU_G = 1.81e-5                   # Pa s
NU_G = MU_G / RHO_G
U_IN = 1.2                       # m/s superficial, at the inlet
G = 9.81
POISSON = 0.35                   # DPMFoam needs one; only enters through E* and G*
V_REF = 0.5                      # m/s, impact velocity at which the contact times are matched
# m/s, fastest-particle speed at which DPMFoam's collision sub-step equals dt_DEM (default of
# --substep-velocity): about what DPMFoam's logged sub-cycle counts imply over the first
# 0.01 s of this bed from rest (0.005 m/s at the start to 0.03 m/s at N = 1000; the count-
# weighted mean 0.012-0.036 m/s in the N = 4000 and 20 000 runs of Nov 2026). The counts go
# as U^(1/5), so a factor 1.5 off U costs < 9 %. A bubbling bed needs about V_REF.
# report.py checks every run's counts.
U_SUB = 0.025
DT_FACTOR = 50                   # CoReDEM: dt_DEM = pi sqrt(m_eff/k_n) / 50 (docs/physics.md)
LATTICE_FAC = 1.05               # start lattice spacing / d_p
JITTER_FAC = 0.02                # +- jitter of each start position / d_p (< (fac - 1)/2)
ALPHAC_MIN = 0.3                 # smallest gas fraction in the gas equations (both codes)


def linear_eta(k, m, e):
    ln_e = math.log(e)
    return 2.0 * math.sqrt(k * m) * abs(ln_e) / math.sqrt(math.pi ** 2 + ln_e ** 2)


def linear_tcol(k, m, e):
    eta = linear_eta(k, m, e)
    return math.pi / math.sqrt(k / m - eta ** 2 / (4.0 * m * m))


def hertz_contact(kn, m, alpha, v0):
    """One head-on contact of OpenFOAM's damped Hertz law, RK4: (restitution, duration)."""
    eta_c = alpha * math.sqrt(m * kn)

    def acc(x, v):
        return -(kn * x ** 1.5 + eta_c * x ** 0.25 * v) / m

    # undamped Hertz duration as the scale of the step
    t_est = 2.87 * (m * m / (kn * kn * v0)) ** 0.2 * (3.0 / 4.0) ** 0.4
    h = t_est / 4000.0
    x, v, t = 0.0, v0, 0.0
    while True:
        xs = max(x, 0.0)
        k1x, k1v = v, acc(xs, v)
        k2x, k2v = v + 0.5 * h * k1v, acc(max(xs + 0.5 * h * k1x, 0.0), v + 0.5 * h * k1v)
        k3x, k3v = v + 0.5 * h * k2v, acc(max(xs + 0.5 * h * k2x, 0.0), v + 0.5 * h * k2v)
        k4x, k4v = v + h * k3v, acc(max(xs + h * k3x, 0.0), v + h * k3v)
        xn = x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
        vn = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if xn <= 0.0 and t > 0.0:
            frac = x / (x - xn)          # linear interpolation to x = 0
            return -(v + frac * (vn - v)) / v0, t + frac * h
        x, v, t = xn, vn, t + h
        if t > 100 * t_est:
            raise RuntimeError("Hertz contact did not end")


def alpha_for_restitution(e):
    """Tsuji damping coefficient alpha giving restitution e (independent of v, k, m)."""
    lo, hi = 0.0, 3.0
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        r, _ = hertz_contact(1.0e3, 1.0e-6, mid, 0.5)
        if r > e:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def hertz_estar_for_tcol(t_target, r_eff, m, alpha, v):
    """E* such that the damped Hertz contact at impact velocity v lasts t_target."""
    e0 = 1.0e6
    _, t0 = hertz_contact(4.0 / 3.0 * math.sqrt(r_eff) * e0, m, alpha, v)
    return e0 * (t0 / t_target) ** 2.5          # t ~ E*^(-2/5)


def openfoam_collision_dt(estar, r_char, rho_max, u_char, steps):
    """5.429675 R (rho/(E* sqrt(U)))^0.4 / steps: the collision-time estimate of OpenFOAM 1912's
    Pair/WallSpringSliderDashpot::nSubCycles for its characteristic radius R and velocity U."""
    return 5.429675 * r_char * (rho_max / (estar * math.sqrt(u_char))) ** 0.4 / steps


def pair_collision_dt(estar_pp, d_min, rho_max, u_fastest, steps):
    """PairSpringSliderDashpot (findMinMaxProperties): R = d_min/4 (two equal spheres of the
    smallest diameter), U = 2 x the fastest particle's |U| + |omega| d/2 (head-on worst case)."""
    return openfoam_collision_dt(estar_pp, d_min / 4.0, rho_max, 2.0 * u_fastest, steps)


def wall_collision_dt(estar_pw, d_min, rho_max, u_fastest, steps):
    """WallSpringSliderDashpot: R = d_min/2, U = the fastest particle's |U| + |omega| d/2."""
    return openfoam_collision_dt(estar_pw, d_min / 2.0, rho_max, u_fastest, steps)


def dpmfoam_substep(dt_cfd, estar_pp, estar_pw, steps_pp, steps_pw, u_fastest):
    """DPMFoam's collision sub-step for a CFD step dt_cfd: PairCollision::nSubCycles is the
    larger of the pair and wall models' ceil(dt_cfd / collision dt)."""
    n = max(math.ceil(dt_cfd / pair_collision_dt(estar_pp, D_P, RHO_P, u_fastest, steps_pp)),
            math.ceil(dt_cfd / wall_collision_dt(estar_pw, D_P, RHO_P, u_fastest, steps_pw)), 1)
    return dt_cfd / n, n


def parameters(u_sub=U_SUB):
    m = RHO_P * math.pi * D_P ** 3 / 6.0
    m_pp, m_pw = 0.5 * m, m
    tcol_pp = linear_tcol(K_N, m_pp, E_N)
    tcol_pw = linear_tcol(K_N, m_pw, E_N)
    dt_dem = math.pi * math.sqrt(m_pp / K_N) / DT_FACTOR  # CoReDEM: undamped duration / 50
    alpha = alpha_for_restitution(E_N)
    r_pp, r_pw = D_P / 4.0, D_P / 2.0            # OpenFOAM's effective radii
    estar_pp = hertz_estar_for_tcol(tcol_pp, r_pp, m_pp, alpha, V_REF)
    estar_pw = hertz_estar_for_tcol(tcol_pw, r_pw, m_pw, alpha, V_REF)
    # pair: E* = E / (2 (1 - nu^2)); wall: 1/E* = (1 - nu_p^2)/E_p + (1 - nu_w^2)/E_w
    e_p = estar_pp * 2.0 * (1.0 - POISSON ** 2)
    inv_w = 1.0 / estar_pw - (1.0 - POISSON ** 2) / e_p
    if inv_w <= 0.0:
        raise RuntimeError("no wall modulus gives the wall contact time")
    e_w = (1.0 - POISSON ** 2) / inv_w
    # collisionResolutionSteps: DPMFoam's collision dt at the design speed u_sub = dt_DEM.
    # Not rounded: OpenFOAM reads it as a scalar, so the sub-steps match exactly at u_sub.
    steps_pp = pair_collision_dt(estar_pp, D_P, RHO_P, u_sub, 1) / dt_dem
    steps_pw = wall_collision_dt(estar_pw, D_P, RHO_P, u_sub, 1) / dt_dem
    _, t_check = hertz_contact(4.0 / 3.0 * math.sqrt(r_pp) * estar_pp, m_pp, alpha, V_REF)
    e_check, _ = hertz_contact(4.0 / 3.0 * math.sqrt(r_pp) * estar_pp, m_pp, alpha, 0.1)
    return {
        "mass": m, "tcol_pp": tcol_pp, "tcol_pw": tcol_pw, "dt_dem": dt_dem,
        "alpha": alpha, "estar_pp": estar_pp, "estar_pw": estar_pw,
        "youngs_particle": e_p, "youngs_wall": e_w,
        "substep_velocity": u_sub,
        "resolution_steps_pair": steps_pp,
        "resolution_steps_wall": steps_pw,
        "dt_dem_dpmfoam_pair": pair_collision_dt(estar_pp, D_P, RHO_P, u_sub, steps_pp),
        "dt_dem_dpmfoam_wall": wall_collision_dt(estar_pw, D_P, RHO_P, u_sub, steps_pw),
        "hertz_tcol_check": t_check, "hertz_e_at_0.1": e_check,
    }


def positions(n, seed):
    """Jittered lattice from the bottom of the column, x fastest, then z, then y."""
    s = LATTICE_FAC * D_P
    nx = int(math.floor(BOX[0] / s + 1e-9))
    nz = int(math.floor(BOX[2] / s + 1e-9))
    per_layer = nx * nz
    layers = (n + per_layer - 1) // per_layer
    if layers * s > 0.8 * BOX[1]:
        raise SystemExit(f"make_case.py: N = {n} needs {layers} lattice layers "
                         f"({layers * s:.3f} m), more than 80 % of the column height")
    ox = 0.5 * (BOX[0] - nx * s)
    oz = 0.5 * (BOX[2] - nz * s)
    rng = random.Random(seed)
    j = JITTER_FAC * D_P
    out = []
    for k in range(n):
        i = k % nx
        l = (k // nx) % nz
        y = k // per_layer
        out.append((ox + (i + 0.5) * s + rng.uniform(-j, j),
                    (y + 0.5) * s + rng.uniform(-j, j) + 0.5 * (s - D_P),
                    oz + (l + 0.5) * s + rng.uniform(-j, j)))
    return out, layers * s


HEADER = """/*--------------------------------*- C++ -*----------------------------------*\\
  Generated by bench/peers/dpmfoam/make_case.py (N = {n})
\\*---------------------------------------------------------------------------*/
FoamFile
{{
    version     2.0;
    format      ascii;
    class       {cls};
    location    "{loc}";
    object      {obj};
}}
"""


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def foam(path, n, cls, loc, obj, body):
    write(path, HEADER.format(n=n, cls=cls, loc=loc, obj=obj) + body)


def block_mesh(inlet_type, outlet_type):
    return f"""scale 1;
vertices
(
    (0 0 0) ({BOX[0]} 0 0) ({BOX[0]} {BOX[1]} 0) (0 {BOX[1]} 0)
    (0 0 {BOX[2]}) ({BOX[0]} 0 {BOX[2]}) ({BOX[0]} {BOX[1]} {BOX[2]}) (0 {BOX[1]} {BOX[2]})
);
blocks ( hex (0 1 2 3 4 5 6 7) ({CELLS[0]} {CELLS[1]} {CELLS[2]}) simpleGrading (1 1 1) );
boundary
(
    inlet  {{ type {inlet_type}; faces ((0 1 5 4)); }}
    outlet {{ type {outlet_type}; faces ((3 7 6 2)); }}
    walls  {{ type wall; faces ((0 4 7 3) (1 2 6 5) (0 3 2 1) (4 5 6 7)); }}
);
"""


def control_dict(app, sim_seconds, write_interval, extra=""):
    return f"""application     {app};
startFrom       startTime;
startTime       0;
stopAt          endTime;
endTime         {sim_seconds};
deltaT          5e-4;
adjustTimeStep  yes;
maxCo           0.5;
maxDeltaT       1e-3;
writeControl    adjustableRunTime;
writeInterval   {write_interval};
purgeWrite      0;
writeFormat     ascii;
writePrecision  8;
writeCompression off;
timeFormat      general;
timePrecision   10;
runTimeModifiable false;
{extra}"""


def write_dpmfoam(out, n, sim, wi, pos, par):
    c = os.path.join(out, "dpmfoam")
    foam(f"{c}/system/blockMeshDict", n, "dictionary", "system", "blockMeshDict",
         block_mesh("wall", "wall"))
    foam(f"{c}/system/controlDict", n, "dictionary", "system", "controlDict",
         control_dict("DPMFoam", sim, wi))
    foam(f"{c}/system/fvSchemes", n, "dictionary", "system", "fvSchemes", """
ddtSchemes      { default Euler; }
gradSchemes     { default Gauss linear; }
divSchemes
{
    default         none;
    div(alphaPhi.air,U.air) Gauss limitedLinearV 1;
    div(((alpha.air*nuEff.air)*dev2(T(grad(U.air))))) Gauss linear;
}
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes   { default corrected; }
""")
    foam(f"{c}/system/fvSolution", n, "dictionary", "system", "fvSolution", """
solvers
{
    p       { solver PCG; preconditioner DIC; tolerance 1e-09; relTol 0.01; }
    pFinal  { $p; relTol 0; }
    "(U.air|k|omega)"      { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-12; relTol 0; }
    "(U.air|k|omega)Final" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-12; relTol 0; }
}
PIMPLE
{
    momentumPredictor yes;
    nOuterCorrectors 1;
    nCorrectors     2;
    nNonOrthogonalCorrectors 0;
    pRefCell        0;
    pRefValue       0;
}
""")
    foam(f"{c}/constant/g", n, "uniformDimensionedVectorField", "constant", "g",
         f"dimensions [0 1 -2 0 0 0 0];\nvalue (0 {-G} 0);\n")
    foam(f"{c}/constant/transportProperties", n, "dictionary", "constant", "transportProperties",
         f"continuousPhase air;\nrho.air {RHO_G};\ntransportModel Newtonian;\nnu {NU_G!r};\n")
    foam(f"{c}/constant/turbulenceProperties.air", n, "dictionary", "constant",
         "turbulenceProperties.air", "simulationType laminar;\n")
    foam(f"{c}/0/U.air", n, "volVectorField", "0", "U.air", f"""dimensions [0 1 -1 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{{
    inlet  {{ type interstitialInletVelocity; inletVelocity uniform (0 {U_IN} 0);
             value uniform (0 {U_IN} 0); phi phi.air; alpha alpha.air; }}
    outlet {{ type pressureInletOutletVelocity; phi phi.air; inletValue uniform (0 0 0);
             value uniform (0 0 0); }}
    walls  {{ type slip; }}
}}
""")
    foam(f"{c}/0/p", n, "volScalarField", "0", "p", """dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    inlet  { type fixedFluxPressure; phi phi.air; value uniform 0; }
    outlet { type fixedValue; value uniform 0; }
    walls  { type fixedFluxPressure; phi phi.air; value uniform 0; }
}
""")
    body = "(\n" + "".join(f"({x!r} {y!r} {z!r})\n" for x, y, z in pos) + ")\n"
    foam(f"{c}/constant/kinematicCloudPositions", n, "vectorField", "constant",
         "kinematicCloudPositions", body)
    rebound = f"{{ type rebound; e {E_N}; mu {MU}; }}"
    foam(f"{c}/constant/kinematicCloudProperties", n, "dictionary", "constant",
         "kinematicCloudProperties", f"""
solution
{{
    active          true;
    coupled         true;
    transient       yes;
    cellValueSourceCorrection off;
    interpolationSchemes {{ rho.air cell; U.air cell; mu.air cell; }}
    integrationSchemes {{ U Euler; }}
    sourceTerms {{ schemes {{ U semiImplicit 1; }} }}
}}

constantProperties
{{
    parcelTypeId    1;
    rhoMin          1e-15;
    minParcelMass   1e-15;
    rho0            {RHO_P};
    youngsModulus   {par['youngs_particle']!r};
    poissonsRatio   {POISSON};
    constantVolume  false;
    alphaMax        {1.0 - ALPHAC_MIN};   // DPMFoam: alphacMin = 1 - alphaMax
}}

subModels
{{
    particleForces
    {{
        ErgunWenYuDrag {{ alphac alpha.air; }}
        gravity;
    }}

    injectionModels
    {{
        model1
        {{
            type            manualInjection;
            massTotal       0;
            parcelBasisType fixed;
            nParticle       1;          // one parcel = one particle
            SOI             0;
            positionsFile   "kinematicCloudPositions";
            U0              (0 0 0);
            sizeDistribution {{ type fixedValue; fixedValueDistribution {{ value {D_P}; }} }}
        }}
    }}

    dispersionModel none;
    patchInteractionModel localInteraction;
    localInteractionCoeffs
    {{
        patches ( inlet {rebound} outlet {rebound} walls {rebound} );
    }}
    heatTransferModel none;
    surfaceFilmModel none;
    stochasticCollisionModel none;
    radiation off;

    collisionModel pairCollision;
    pairCollisionCoeffs
    {{
        maxInteractionDistance {D_P};
        writeReferredParticleCloud no;
        pairModel pairSpringSliderDashpot;
        pairSpringSliderDashpotCoeffs
        {{
            useEquivalentSize no;
            alpha           {par['alpha']!r};
            b               1.5;
            mu              {MU};
            cohesionEnergyDensity 0;
            collisionResolutionSteps {par['resolution_steps_pair']!r};
        }};
        wallModel wallSpringSliderDashpot;
        wallSpringSliderDashpotCoeffs
        {{
            useEquivalentSize no;
            collisionResolutionSteps {par['resolution_steps_wall']!r};
            youngsModulus   {par['youngs_wall']!r};
            poissonsRatio   {POISSON};
            alpha           {par['alpha']!r};
            b               1.5;
            mu              {MU};
            cohesionEnergyDensity 0;
        }};
        U U.air;
    }}
}}

cloudFunctions {{}}
""")


def write_coredem(out, n, sim, wi, pos, heat=False):
    c = os.path.join(out, "coredem")
    o = os.path.join(c, "openfoam")
    foam(f"{o}/system/blockMeshDict", n, "dictionary", "system", "blockMeshDict",
         block_mesh("patch", "patch"))
    foam(f"{o}/system/controlDict", n, "dictionary", "system", "controlDict",
         control_dict("coredemFoam", "1e30", wi))
    foam(f"{o}/system/fvSchemes", n, "dictionary", "system", "fvSchemes", """
ddtSchemes      { default Euler; }
gradSchemes     { default Gauss linear; }
divSchemes
{
    default         none;
    div(alphaPhi,U) Gauss limitedLinearV 1;
    div(alphaPhi,T) Gauss limitedLinear 1;
    div(alphaPhi,Yi) Gauss limitedLinear01 1;
    div(((alphac*nuEff)*dev2(T(grad(U))))) Gauss linear;
}
laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; }
snGradSchemes   { default corrected; }
""")
    foam(f"{o}/system/fvSolution", n, "dictionary", "system", "fvSolution", """
solvers
{
    p       { solver PCG; preconditioner DIC; tolerance 1e-09; relTol 0.01; }
    pFinal  { $p; relTol 0; }
    U       { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-12; relTol 0; }
    UFinal  { $U; }
    "(T|Yi)(Final)?" { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-09; relTol 0; maxIter 20; }
}
PIMPLE
{
    momentumPredictor yes;
    nOuterCorrectors 1;
    nCorrectors     2;
    nNonOrthogonalCorrectors 0;
    pRefCell        0;
    pRefValue       0;
}
""")
    foam(f"{o}/constant/g", n, "uniformDimensionedVectorField", "constant", "g",
         f"dimensions [0 1 -2 0 0 0 0];\nvalue (0 {-G} 0);\n")
    foam(f"{o}/constant/transportProperties", n, "dictionary", "constant",
         "transportProperties", f"""transportModel Newtonian;
nu {NU_G!r};
rho {RHO_G};
cp 1006;
kappa 0.0257;
D 2e-05;
pressureDropPatches (inlet outlet);
""")
    foam(f"{o}/constant/turbulenceProperties", n, "dictionary", "constant",
         "turbulenceProperties", "simulationType laminar;\n")
    foam(f"{o}/0/U", n, "volVectorField", "0", "U", f"""dimensions [0 1 -1 0 0 0 0];
internalField uniform (0 0 0);
boundaryField
{{
    inlet  {{ type interstitialInletVelocity; inletVelocity uniform (0 {U_IN} 0);
             value uniform (0 {U_IN} 0); alpha alphac; }}
    outlet {{ type pressureInletOutletVelocity; value uniform (0 0 0); }}
    walls  {{ type slip; }}
}}
""")
    foam(f"{o}/0/p", n, "volScalarField", "0", "p", """dimensions [0 2 -2 0 0 0 0];
internalField uniform 0;
boundaryField
{
    inlet  { type fixedFluxPressure; value uniform 0; }
    outlet { type fixedValue; value uniform 0; }
    walls  { type fixedFluxPressure; value uniform 0; }
}
""")
    foam(f"{o}/0/T", n, "volScalarField", "0", "T", """dimensions [0 0 0 1 0 0 0];
internalField uniform 293.15;
boundaryField
{
    inlet  { type fixedValue; value uniform 293.15; }
    outlet { type inletOutlet; inletValue uniform 293.15; value uniform 293.15; }
    walls  { type zeroGradient; }
}
""")
    h = [b / k for b, k in zip(BOX, CELLS)]
    lines = [
        "# Generated by bench/peers/dpmfoam/make_case.py: the DPMFoam peer comparison's bed",
        f"name: dpmfoam-peer-{n}",
        f"description: {n} glass beads (1 mm) in a 4 x 20 x 1 cm column, air at {U_IN} m/s",
        "time:",
        f"  end: {sim}",
        "  dt: 5.0e-4",
        "  adaptive: {courant: 0.5, dt_min: 1.0e-5, dt_max: 1.0e-3, max_growth: 1.2}",
        "grid:",
        "  origin: [0.0, 0.0, 0.0]",
        f"  spacing: [{h[0]!r}, {h[1]!r}, {h[2]!r}]",
        f"  cells: [{CELLS[0]}, {CELLS[1]}, {CELLS[2]}]",
        f"gravity: [0.0, {-G}, 0.0]",
        "gas_properties:",
        f"  density: {RHO_G}",
        f"  viscosity: {MU_G}",
        "  conductivity: 0.0257",
        "  cp: 1006.0",
        "  temperature: 293.15",
        "  pressure: 101325.0",
        "materials:",
        "  - name: glass",
        f"    density: {RHO_P}",
        f"    k_n: {K_N}",
        f"    e_n: {E_N}",
        f"    friction: {MU}",
        "    cp: 840.0",
        "    conductivity: 1.0",
        "particles:",
        "  - name: beads",
        "    material: glass",
        f"    diameter: {D_P}",
        "    temperature: 293.15",
        "    positions:",
    ]
    lines += [f"      - [{x!r}, {y!r}, {z!r}]" for x, y, z in pos]
    lines += [
        "walls:",
        f"  box: {{min: [0.0, 0.0, 0.0], max: [{BOX[0]}, {BOX[1]}, {BOX[2]}]}}",
        "  material: glass",
        "cfd:",
        "  participant: coredemFoam",
        "  case: openfoam",
    ]
    lines += [
        "dem:",
        "  backend: cpu",
        "  threads: 2",
    ]
    # one gas-fraction clip for the gas and the DEM's drag, DPMFoam's 1 - alphaMax
    lines += ["models:", f"  eps_min: {ALPHAC_MIN}"]
    if not heat:
        # DPMFoam runs without heat transfer (heatTransferModel none): so does the DEM here
        lines += ["  heat: \"off\""]
    lines += [
        "checkpoint:",
        "  every_steps: 0",
        "output:",
        "  every: 1000000",
    ]
    write(f"{c}/case.yaml", "\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("n", type=int)
    ap.add_argument("sim_seconds", type=float)
    ap.add_argument("outdir")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--substep-velocity", type=float, default=U_SUB, metavar="U",
                    help="speed (m/s) of the fastest particle at which DPMFoam's collision "
                         f"sub-step equals CoReDEM's dt_DEM (default {U_SUB})")
    a = ap.parse_args()
    if a.n < 1:
        sys.exit("make_case.py: N must be >= 1")
    if a.sim_seconds <= 0:
        sys.exit("make_case.py: SIM_SECONDS must be > 0")
    if not a.substep_velocity > 0:
        sys.exit("make_case.py: --substep-velocity must be > 0 (m/s)")
    par = parameters(a.substep_velocity)
    pos, height = positions(a.n, a.seed)
    wi = a.sim_seconds / 20.0            # 20 field writes: the averages use the second half
    for sub in ("dpmfoam", "coredem"):
        shutil.rmtree(os.path.join(a.outdir, sub), ignore_errors=True)
    write_dpmfoam(a.outdir, a.n, a.sim_seconds, wi, pos, par)
    write_coredem(a.outdir, a.n, a.sim_seconds, wi, pos)
    bed_weight = a.n * par["mass"] * G / (BOX[0] * BOX[2])
    print(f"N = {a.n}")
    print(f"sim_seconds = {a.sim_seconds}")
    print(f"write_interval_s = {wi}")
    print(f"start_lattice_height_m = {height:.4f}")
    print(f"bed_weight_per_area_Pa = {bed_weight:.2f}")
    for k in ("tcol_pp", "tcol_pw", "dt_dem", "alpha", "estar_pp", "estar_pw",
              "youngs_particle", "youngs_wall", "hertz_tcol_check", "hertz_e_at_0.1"):
        v = par[k]
        print(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}")
    # Full precision: report.py reads these back to check DPMFoam's sub-cycle counts.
    for k in ("substep_velocity", "resolution_steps_pair", "resolution_steps_wall",
              "estar_pp", "estar_pw"):
        print(f"{k}_exact = {par[k]!r}")
    print(f"dt_dem_coredem = {par['dt_dem']:.6g}")
    print(f"dt_dem_dpmfoam = {min(par['dt_dem_dpmfoam_pair'], par['dt_dem_dpmfoam_wall']):.6g}"
          f"  (pair {par['dt_dem_dpmfoam_pair']:.6g}, wall {par['dt_dem_dpmfoam_wall']:.6g}; "
          f"at a fastest particle of {a.substep_velocity} m/s)")
    for u in (0.005, U_SUB, 0.1, 0.5):
        dt_p = pair_collision_dt(par["estar_pp"], D_P, RHO_P, u, par["resolution_steps_pair"])
        dt_w = wall_collision_dt(par["estar_pw"], D_P, RHO_P, u, par["resolution_steps_wall"])
        print(f"dt_dem_dpmfoam_at_{u}_m_s = {min(dt_p, dt_w):.6g}  "
              f"({min(dt_p, dt_w) / par['dt_dem']:.3f} x dt_dem_coredem)")


if __name__ == "__main__":
    main()
