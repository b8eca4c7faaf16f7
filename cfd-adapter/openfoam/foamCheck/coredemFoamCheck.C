// coredemFoamCheck — CoReDEM's proof application for the OpenFOAM build.
//
// Transient, incompressible, volume-averaged gas flow without particles, solved with PISO:
//
//   d(ac)/dt + div(ac U) = 0
//   d(ac U)/dt + div(ac U U) - U (d(ac)/dt + div(ac U)) = -ac grad(p) + div(ac nuEff dev2(grad U))
//                                                          + fvOptions
//
// with ac the gas volume fraction (field "alphac", read if present, otherwise 1), U the
// interstitial gas velocity and p the kinematic pressure: the "Model A" split of docs/physics.md §1,
// constant density. With alphac = 1 it is the plain incompressible Navier-Stokes equations
// (what pisoFoam solves), and a uniform alphac cancels out of every term, which the
// integration test uses as a consistency check.
//
// It exists to prove that our own application compiles against the headers prepared by
// scripts/openfoam-headers.sh and runs with Debian's libraries, using the same library stack
// as the coupled solver coredemFoam: singlePhaseTransportModel, the phase-weighted turbulence
// models of libDPMTurbulenceModels, and fvOptions.

#include "fvCFD.H"
#include "singlePhaseTransportModel.H"
#include "PhaseIncompressibleTurbulenceModel.H"
#include "pisoControl.H"
#include "fvOptions.H"

int main(int argc, char* argv[])
{
    argList::addNote
    (
        "CoReDEM proof application: transient incompressible volume-averaged PISO solver"
        " (gas volume fraction alphac, no particles)."
    );

    #include "setRootCase.H"
    #include "createTime.H"
    #include "createMesh.H"

    pisoControl piso(mesh);

    #include "createFields.H"

    scalar cumulativeContErr = 0;

    turbulence->validate();

    Info<< "\nStarting time loop\n" << endl;

    while (runTime.loop())
    {
        Info<< "Time = " << runTime.timeName() << nl << endl;

        #include "CourantNo.H"

        #include "UEqn.H"

        while (piso.correct())
        {
            #include "pEqn.H"
        }

        #include "alphacContinuityErrs.H"

        laminarTransport.correct();
        turbulence->correct();

        runTime.write();

        Info<< "ExecutionTime = " << runTime.elapsedCpuTime() << " s"
            << "  ClockTime = " << runTime.elapsedClockTime() << " s"
            << nl << endl;
    }

    Info<< "End\n" << endl;

    return 0;
}
