/*---------------------------------------------------------------------------*\
  diefill: coupled CFD-DEM simulation of powder die filling.
-------------------------------------------------------------------------------
Application
    checkCellLocator

Description
    Test utility of tests/diefillFoam/run: diefill::cellLocator (the void
    fraction's cell search) against OpenFOAM's polyMesh::findCell (octree and
    tet decomposition) on the case's mesh, or on each processor's part with
    -parallel.  Points: every cell centre, points just inside and just
    outside every face (towards and past its centre from the cell's centre),
    every mesh point, and random points in the mesh's box grown by a tenth.
    The two must name the same cell, or both name a cell that holds the point
    (a point on a face shared by two cells), or both find none.  Exits with
    an error naming the first disagreements.

\*---------------------------------------------------------------------------*/

#include "argList.H"
#include "Time.H"
#include "polyMesh.H"
#include "Random.H"
#include "DynamicField.H"

// One translation unit: the locator exactly as the solver compiles it
#include "cellLocator.C"

using namespace Foam;

int main(int argc, char *argv[])
{
    argList::addNote
    (
        "Compares diefill::cellLocator with polyMesh::findCell on the case's mesh"
    );
    argList::addOption("points", "N", "random points (default 20000)");

    #include "setRootCase.H"
    #include "createTime.H"
    #include "createPolyMesh.H"

    const label nRandom = args.getOrDefault<label>("points", 20000);

    // findCell builds these with collectives on first use: build them on
    // every rank before the loops below
    (void)mesh.tetBasePtIs();
    (void)mesh.cellTree();

    const diefill::cellLocator locator(mesh);

    const pointField& cc = mesh.cellCentres();
    const pointField& fc = mesh.faceCentres();
    DynamicField<point> samples;
    samples.append(cc);
    forAll(mesh.cells(), celli)
    {
        for (const label facei : mesh.cells()[celli])
        {
            samples.append(cc[celli] + 0.999*(fc[facei] - cc[celli]));
            samples.append(cc[celli] + 1.001*(fc[facei] - cc[celli]));
        }
    }
    samples.append(mesh.points());
    if (mesh.nCells())
    {
        boundBox bb(mesh.points(), false);
        bb.inflate(0.1);
        Random rng(1234 + Pstream::myProcNo());
        for (label i = 0; i < nRandom; ++i)
        {
            samples.append(rng.position<point>(bb.min(), bb.max()));
        }
    }

    label inCell = 0, inNone = 0, onSharedFace = 0, disagree = 0;
    for (const point& p : samples)
    {
        const label found = locator.findCell(p);
        const label expected = mesh.findCell(p);
        if (found == expected)
        {
            ++(found >= 0 ? inCell : inNone);
        }
        else if
        (
            found >= 0 && expected >= 0
         && mesh.pointInCell(p, found, polyMesh::CELL_TETS)
        )
        {
            ++onSharedFace;
        }
        else
        {
            if (++disagree <= 5)
            {
                Pout<< "checkCellLocator: at " << p << " the locator gives cell "
                    << found << ", polyMesh::findCell " << expected << endl;
            }
        }
    }

    label nSamples = samples.size();
    reduce(nSamples, sumOp<label>());
    reduce(inCell, sumOp<label>());
    reduce(inNone, sumOp<label>());
    reduce(onSharedFace, sumOp<label>());
    reduce(disagree, sumOp<label>());
    Info<< "checkCellLocator: " << nSamples << " points over "
        << Pstream::nProcs() << " processor(s) ("
        << returnReduce(mesh.nCells(), sumOp<label>()) << " cells, "
        << locator.nBins() << " bins on the master): " << inCell
        << " in the same cell, " << inNone << " in none, " << onSharedFace
        << " on a shared face (both cells hold it), " << disagree
        << " disagree" << endl;

    if (disagree)
    {
        FatalErrorInFunction
            << disagree << " of " << nSamples << " points are located"
            << " differently by the locator and polyMesh::findCell"
            << exit(FatalError);
    }

    Info<< "End" << endl;
    return 0;
}


// ************************************************************************* //
