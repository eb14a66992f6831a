/*---------------------------------------------------------------------------*\
  diefill: coupled CFD-DEM simulation of powder die filling.
\*---------------------------------------------------------------------------*/

#include "parallelLaunch.H"

#include <cstdlib>
#include <cstring>

std::string Foam::diefill::parallelLaunchProblem(int argc, char* argv[])
{
    // (argList starts MPI before it looks at -help: with -parallel it aborts
    // there too.)
    bool parallel = false;
    for (int i = 1; i < argc; ++i)
    {
        parallel = parallel || std::strcmp(argv[i], "-parallel") == 0;
    }
    if (!parallel)
    {
        return {};
    }

    // The number of processes, where the launcher sets it in each process.
    // (Not SLURM_NTASKS: a batch job's whole environment holds it, so it
    // would count a launch of another MPI with 1 when the job has one task.)
    const char* const sizeVariables[] =
        {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MV2_COMM_WORLD_SIZE"};
    const char* sizeText = nullptr;
    for (const char* name : sizeVariables)
    {
        if ((sizeText = std::getenv(name)) != nullptr) break;
    }
    // Launchers that say only that they started this process: left to
    // OpenFOAM's own check.
    const bool launched = sizeText != nullptr
        || std::getenv("PMIX_RANK") != nullptr
        || std::getenv("SLURM_PROCID") != nullptr;
    if (launched && (sizeText == nullptr || std::atoi(sizeText) != 1))
    {
        return {};
    }

    const std::string what = launched
        ? "this is an MPI launch of 1 process"
        : "this process was started without an MPI launcher";
    return "-parallel needs an MPI launch of 2 or more processes; " + what + ".\n"
           "    Decompose the case first (decomposePar; the number of parts is numberOfSubdomains\n"
           "    in system/decomposeParDict), then run\n"
           "        mpirun -np <numberOfSubdomains> diefillFoam -parallel\n"
           "    or run diefillFoam without -parallel on one process.";
}
