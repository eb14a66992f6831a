#include "voidFractionModel.H"
#include "checkKeywords.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(voidFractionModel, 0);
    defineRunTimeSelectionTable(voidFractionModel, dictionary);
}
}

Foam::diefill::voidFractionModel::voidFractionModel
(
    const fvMesh& mesh,
    const dictionary& coeffs
)
:
    mesh_(mesh),
    coeffs_(coeffs),
    localBounds_(mesh.points()),
    locator_(mesh)
{}


bool Foam::diefill::voidFractionModel::outsideLocalBounds
(
    const point& centre,
    scalar radius
) const
{
    // An empty processor has an inverted box: everything is outside.
    if (mesh_.nCells() == 0)
    {
        return true;
    }
    const vector r(radius, radius, radius);
    return !localBounds_.overlaps(boundBox(centre - r, centre + r));
}


Foam::label Foam::diefill::voidFractionModel::findCell
(
    const point& p,
    label hint
) const
{
    if (hint >= 0)
    {
        if (mesh_.pointInCell(p, hint, polyMesh::FACE_PLANES))
        {
            return hint;
        }
        for (const label nbr : mesh_.cellCells()[hint])
        {
            if (mesh_.pointInCell(p, nbr, polyMesh::FACE_PLANES))
            {
                return nbr;
            }
        }
    }
    return locator_.findCell(p);
}


Foam::autoPtr<Foam::diefill::voidFractionModel>
Foam::diefill::voidFractionModel::New
(
    const word& name,
    const fvMesh& mesh,
    const dictionary& couplingDict
)
{
    auto cstrIter = dictionaryConstructorTablePtr_->cfind(name);

    if (!cstrIter.found())
    {
        FatalIOErrorInLookup
        (
            couplingDict,
            "voidFractionModel",
            name,
            *dictionaryConstructorTablePtr_
        ) << exit(FatalIOError);
    }

    Info<< "    void fraction model: " << name << endl;

    autoPtr<voidFractionModel> model
    (
        cstrIter()(mesh, modelCoeffs(couplingDict, name))
    );
    Info<< "    cell search: hint, its face neighbours, then "
        << model->locator_.nBins() << " bins of "
        << model->locator_.cellsPerBin() << " cells on average"
        << (Pstream::parRun() ? " (master's part)" : "") << endl;
    return model;
}
