#include "particleForce.H"
#include "checkKeywords.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(particleForce, 0);
    defineRunTimeSelectionTable(particleForce, dictionary);
}
}

Foam::diefill::particleForce::particleForce(const dictionary& coeffs)
:
    coeffs_(coeffs)
{}


Foam::autoPtr<Foam::diefill::particleForce> Foam::diefill::particleForce::New
(
    const word& name,
    const dictionary& couplingDict
)
{
    auto cstrIter = dictionaryConstructorTablePtr_->cfind(name);

    if (!cstrIter.found())
    {
        FatalIOErrorInLookup
        (
            couplingDict,
            "particleForce",
            name,
            *dictionaryConstructorTablePtr_
        ) << exit(FatalIOError);
    }

    Info<< "    force model: " << name << endl;

    return autoPtr<particleForce>
    (
        cstrIter()(modelCoeffs(couplingDict, name))
    );
}
