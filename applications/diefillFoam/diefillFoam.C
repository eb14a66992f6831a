/*---------------------------------------------------------------------------*\
  diefill: coupled CFD-DEM simulation of powder die filling.
  Built on OpenFOAM v1912 (GPL-3.0-or-later).
-------------------------------------------------------------------------------
Application
    diefillFoam

Description
    Transient solver for the air in a die-filling process, coupled to the DEM
    engine demLib.

    The air is incompressible and Newtonian; laminar by default, with the
    OpenFOAM turbulence framework available (constant/turbulenceProperties).
    Pressure-velocity coupling: PIMPLE (controls in system/fvSolution).
    The DEM side of the coupling lives in demCoupling.H.

    Required fields
        U   | Air velocity [m/s]
        p   | Kinematic pressure, p/rho [m2/s2]

\*---------------------------------------------------------------------------*/

#include "fvCFD.H"
#include "singlePhaseTransportModel.H"
#include "turbulentTransportModel.H"
#include "pimpleControl.H"
#include "fvOptions.H"

#include "demCoupling.H"

// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

int main(int argc, char *argv[])
{
    argList::addNote
    (
        "Transient solver for the air in powder die filling,"
        " coupled to the DEM engine demLib."
    );

    #include "postProcess.H"

    #include "addCheckCaseOptions.H"
    #include "setRootCaseLists.H"
    #include "createTime.H"
    #include "createMesh.H"
    #include "createControl.H"
    #include "createTimeControls.H"
    #include "initContinuityErrs.H"
    #include "createFields.H"
    #include "CourantNo.H"
    #include "setInitialDeltaT.H"

    turbulence->validate();

    diefill::demCoupling dem(mesh);

    // * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

    Info<< "\nStarting time loop\n" << endl;

    while (runTime.run())
    {
        #include "readTimeControls.H"
        #include "CourantNo.H"
        #include "setDeltaT.H"

        ++runTime;

        Info<< "Time = " << runTime.timeName() << nl << endl;

        // --- Pressure-velocity PIMPLE corrector loop
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

        runTime.write();

        runTime.printExecutionTime(Info);
    }

    Info<< "End\n" << endl;

    return 0;
}


// ************************************************************************* //
