// coredemFoam — the OpenFOAM participant of a coupled CoReDEM run (docs/coredemFoam.md).
//
// Transient, incompressible, volume-averaged gas ("Model A", constant properties) solved with
// PIMPLE in the DPMFoam manner: the particles reach the gas only through the gas volume
// fraction alphac and source fields. Every step the orchestrator grants (dt, step):
//
//   1. send the gas at the start of the step (U, grad p, T, properties, Y) to the DEM server,
//      which sub-cycles its particles over dt and answers with sub-step-averaged sources:
//      eps_g, K_sl, K_sl*U_s, H, H*T_p, R_k, Q_hom on the coupling grid (PCM cells), mapped to
//      and from this mesh by couplingGrid.H (any mesh the grid covers);
//   2. advance the gas over the same dt with them: alphac (including d(alphac)/dt in
//      continuity), implicit drag Sp(K_sl/rho) + explicit K_sl U_s/rho, particle heat implicit
//      in T, species sources;
//   3. report the Courant number (for the next dt) and the cumulative ledgers in StepDone, and
//      on a checkpoint grant write the state as a binary time directory and list it.
//
// Source layout (DPMFoam-style): createCoupling.H (handshake, grid, restart), createFields.H,
// createCouplingFields.H (the exchanged quantities of couplingFields.H, registered with the
// exchange of couplingExchange.H, and the checkpointed fields of checkpoint.H), createLedgers.H
// + updateLedgers.H + boundaryLedgers.H (the named ledgers of gasLedgers.H), UEqn.H, pEqn.H,
// TEqn.H, YEqn.H, and the stage timers of stageTimers.H.
//
// Command line: coredemFoam -case DIR [-restart FILE] [-control EP] [-dem EP] [-session ID]
// [-timeout S] [-timers] (endpoints default to COREDEM_CONTROL_ENDPOINT, COREDEM_DEM_ENDPOINT,
// COREDEM_SESSION). -timers: per-stage wall time per CFD step, a table at the end and
// DIR/../timers-cfd.json (the run folder under `coredem run`; decomposed: rank 0's, the other
// ranks' in timers-cfd-processorN.json). -parallel: a decomposed run (docs/coredemFoam.md).

#include "fvCFD.H"
#include "singlePhaseTransportModel.H"
#include "PhaseIncompressibleTurbulenceModel.H"
#include "pimpleControl.H"
#include "processorFvPatch.H"
#include "fvOptions.H"
#include "rhoReactionThermo.H"
#include "multivariateScheme.H"

#include "checkpoint.H"
#include "couplingExchange.H"
#include "couplingFields.H"
#include "couplingGrid.H"
#include "gasLedgers.H"
#include "rankControl.H"
#include "reconstructCells.H"
#include "stageTimers.H"

#include "coredem/client/participant.h"
#include "coredem/common/version.h"

#include <fstream>
#include <string>
#include <vector>

int main(int argc, char* argv[])
{
    #include "addCouplingOptions.H"
    #include "setRootCase.H"
    #include "createTime.H"
    #include "blockMeshIfMissing.H"
    #include "createMesh.H"
    pimpleControl pimple(mesh);
    #include "readGravitationalAcceleration.H"
    #include "createThermo.H"
    #include "createCoupling.H"
    #include "createFields.H"

    // Old-time values exist from the start so that d(alphac)/dt of the first step after a
    // restart uses the checkpoint's fraction, as an uninterrupted run does.
    alphac.oldTime();

    if (!variableDensity)
    {
        turbulence->validate();
    }

    #include "createCouplingFields.H"
    #include "createLedgers.H"

    scalar cumulativeContErr = 0;
    label steps = 0;

    // Simulated time as the orchestrator sums it (compensated, common/compensated_sum.h), so that
    // the step it shortens to land on time.end or an output time ends there exactly: OpenFOAM's
    // own t += dt drifts (4.999999999999981 for 5 after 279 adaptive steps).
    ::coredem::CompensatedSum timeSum(runTime.value());

    Info<< "\nStarting time loop\n" << endl;

    while (coupling.isRunning())
    {
        const label step = label(coupling.step());
        const scalar dt = coupling.dt();
        timers.startStep();

        // 1. gas at the start of the step -> DEM, sources of the step <- DEM.
        exchange.exchange(step, dt);

        runTime.setDeltaT(dt, false);
        ++runTime;
        timeSum.add(dt);
        runTime.setTime(timeSum.value(), runTime.timeIndex());
        Info<< "Step " << step << "  Time = " << runTime.timeName() << "  deltaT = " << dt
            << nl << endl;

        alphac.primitiveFieldRef() = gasFraction.value();
        alphac.correctBoundaryConditions();
        alphacf = fvc::interpolate(alphac);

        // 2. the gas over the same step (variable density: gasStepVD.H, with its ledgers).
        if (variableDensity)
        {
            #include "gasStepVD.H"
        }
        else
        {
            singlePhaseTransportModel& laminarTransport = laminarTransportPtr();
            while (pimple.loop())
            {
                timers.tic();
                #include "UEqn.H"
                timers.toc(StageTimers::UEqn);

                while (pimple.correct())
                {
                    timers.tic();
                    #include "pEqn.H"
                    timers.toc(StageTimers::PEqn);
                }

                if (pimple.turbCorr())
                {
                    laminarTransport.correct();
                    turbulence->correct();
                }
            }
            timers.tic();
            #include "TEqn.H"
            timers.toc(StageTimers::TEqn);
            timers.tic();
            #include "YEqn.H"
            timers.toc(StageTimers::YEqn);
            #include "alphacContinuityErrs.H"

            // 3. ledgers (cumulative) and the Courant number of this step.
            #include "updateLedgers.H"
        }
        #include "couplingCourantNo.H"

        // 4. output, checkpoint, StepDone and the wait for the next grant. Output times are the
        // orchestrator's (output in case.yaml): the gas fields are written on the steps whose
        // particle snapshot it takes, never at controlDict's writeInterval.
        if (coupling.requiresOutput())
        {
            runTime.writeNow();
        }
        std::vector<std::string> files;
        if (coupling.requiresCheckpoint())
        {
            files = checkpoint.write(coupling.checkpointDir(), coupling.step(), ledgers);
        }
        try
        {
            timers.tic();
            // Decomposed: the master reports the step (CoNum and the ledgers are reduced over
            // the processors) and the others follow its next grant (rankControl.H).
            if (Pstream::master()) coupling.advance(CoNum, ledgers.report(), files);
            followMaster(coupling);
            timers.toc(StageTimers::Advance);
        }
        catch (const ::coredem::client::ClientError& e)
        {
            FatalErrorInFunction << "coupling, step " << step << ": " << e.what()
                << exit(FatalError);
        }

        runTime.printExecutionTime(Info);
        ++steps;
        timers.endStep();
    }

    #include "writeTimers.H"

    runTime.writeNow();
    Info<< "Run finished after " << steps << " steps: " << coupling.shutdownReason().c_str()
        << nl << "End\n" << endl;
    coupling.finalize();
    return 0;
}
