/*---------------------------------------------------------------------------*\
  diefill: coupled CFD-DEM simulation of powder die filling.
  Built on OpenFOAM v1912 (GPL-3.0-or-later).
-------------------------------------------------------------------------------
Application
    diefillFoam

Description
    Transient solver for the air in a die-filling process, coupled to the DEM
    engine demLib by unresolved (volume-averaged) drag.

    The air is incompressible and Newtonian; its volume-averaged equations
    carry the void fraction of the powder (model A or B of Zhou et al. 2010);
    laminar by default, with the OpenFOAM turbulence framework available
    (constant/turbulenceProperties).  Pressure-velocity coupling: PIMPLE.
    Each fluid step the DEM takes deltaT/demTimeStep steps; void fraction and
    drag are exchanged once per fluid step (docs/coupling.md).

    Case files
        constant/transportProperties | nu [m2/s], rho [kg/m3] of the air
        constant/couplingProperties  | coupling models (docs/coupling.md)
        constant/demProperties       | the DEM (docs/case-reference.md)
        0/U, 0/p                     | interstitial velocity, p/rho
        0/alpha.air                  | optional: void-fraction BCs
        <time>/uniform/particleForces| written: fluid forces on the particles,
                                     | read back on a restart with the DEM
                                     | restart file of the same step

\*---------------------------------------------------------------------------*/

#include "fvCFD.H"
#include "singlePhaseTransportModel.H"
#include "PhaseIncompressibleTurbulenceModel.H"
#include "pimpleControl.H"
#include "fvOptions.H"
#include "zeroGradientFvPatchFields.H"

#include "demCoupling.H"
#include "parallelLaunch.H"
#include "phaseTimes.H"
#include "progressReport.H"
#include "stopSignal.H"

#include <iostream>

// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

int main(int argc, char *argv[])
{
    argList::addNote
    (
        "Transient solver for the air in powder die filling,"
        " coupled to the DEM engine demLib by unresolved drag"
        " (constant/couplingProperties, constant/demProperties)."
    );

    // -parallel on one process: OpenFOAM would abort with a stack trace.
    {
        const std::string problem = diefill::parallelLaunchProblem(argc, argv);
        if (!problem.empty())
        {
            std::cerr << "\n--> diefillFoam: " << problem << "\n" << std::endl;
            return 1;
        }
    }

    // No -postProcess and no -dry-run: both would start the DEM (and write
    // its output over an earlier run's) before they could do anything.
    #include "setRootCaseLists.H"
    #include "createTime.H"
    #include "createMesh.H"
    #include "createControl.H"
    #include "createTimeControls.H"
    #include "createFields.H"
    #include "CourantNo.H"
    #include "setInitialDeltaT.H"

    turbulence->validate();

    // Forces for the first DEM interval: from the initial air state, or as
    // written at the restart time (then the continued run repeats the
    // uninterrupted one)
    if (coupling.restartForces())
    {
        Info<< "Coupling: fluid forces on the particles from "
            << coupling.restartForcesFile() << endl;
    }
    else
    {
        coupling.updateExchange(Ksp, KUp);
        coupling.updateParticleForces(Ksp, KUp);
    }

    // * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

    Info<< "\nStarting time loop\n" << endl;

    // A line with the ETA every 30 s of wall time (long die-filling runs)
    diefill::progressReport progress(runTime);
    diefill::stopSignal stop;
    // Where the wall time goes (printed at the end)
    diefill::phaseTimes phases;

    while (runTime.run())
    {
        #include "readTimeControls.H"
        #include "CourantNo.H"
        #include "setDeltaT.H"

        ++runTime;

        Info<< "Time = " << runTime.timeName() << nl << endl;

        // --- Particles to the new time, then their volume and drag to the air
        phases.start(phases.dem);
        coupling.evolve();
        phases.start(phases.coupling);
        coupling.updateVoidFraction();
        alphaf = fvc::interpolate(alpha);
        alphaPhi = alphaf*phi;
        if (coupling.modelA())
        {
            alphaP = alpha;
            // Linear (scheme interpolate(alphaP)), not alphaf's scheme: the
            // air then takes alphaPf of each face's pressure force and the
            // particles, through the Gauss gradient, the rest
            // (docs/coupling.md, "Air equations").
            alphaPf = fvc::interpolate(alphaP);
        }
        coupling.updateExchange(Ksp, KUp);

        // --- Pressure-velocity PIMPLE corrector loop
        phases.start(phases.air);
        while (pimple.loop())
        {
            #include "UEqn.H"

            // --- Pressure corrector loop
            while (pimple.correct())
            {
                #include "pEqn.H"
            }

            if (pimple.turbCorr())
            {
                laminarTransport.correct();
                turbulence->correct();
            }
        }

        // --- The air's new state to the particles for the next DEM interval
        phases.start(phases.coupling);
        coupling.updateParticleForces(Ksp, KUp);

        phases.start(phases.output);
        if (runTime.writeTime())
        {
            coupling.write();
        }
        runTime.write();
        phases.stop();

        runTime.printExecutionTime(Info);

        progress.update();

        if (stop.requested())
        {
            Info<< "diefillFoam: stopped by " << stop.name() << " at t = "
                << runTime.timeName() << " s: the air fields, particle forces and"
                << " DEM restart file of this time are written; run again to"
                << " continue from them" << nl << endl;
            break;
        }
    }

    // The end time is written even when it is not a multiple of writeInterval,
    // with the particle forces that go with it (a later continuation needs both)
    phases.start(phases.output);
    if (!runTime.writeTime())
    {
        runTime.writeNow();
        coupling.write();
    }

    coupling.finish();
    phases.stop();
    phases.report(Info(), coupling.demExchangeSeconds());

    if (stop.requested())
    {
        // Everything is written.  Not 'return': argList's destructor ends the
        // process with UPstream::exit(0), which would report a stopped run as
        // finished.
        UPstream::exit(128 + stop.signal());
    }

    Info<< "End\n" << endl;

    return 0;
}


// ************************************************************************* //
