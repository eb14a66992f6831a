#include "checkKeywords.H"
#include "error.H"

#include "demLib/dictionary.hpp"

#include <string>
#include <vector>


void Foam::diefill::checkKeywords
(
    const dictionary& dict,
    const wordList& known
)
{
    for (const entry& e : dict)
    {
        const word& key = e.keyword();
        if (key == "FoamFile" || known.found(key))
        {
            continue;
        }
        // demLib's "did you mean", the same as for demProperties.
        // (a word: OpenFOAM's streams print a std::string in quotes)
        const word suggestion
        (
            dem::closestWord(key, std::vector<std::string>(known.begin(), known.end()))
        );
        // A sub-dictionary is named file.block: the file is the part
        // before the first dot of the last path component.
        std::string file = dict.name();
        const auto slash = file.rfind('/');
        const auto dot = file.find('.', slash == std::string::npos ? 0 : slash + 1);
        if (dot != std::string::npos)
        {
            file.erase(dot);
        }
        FatalIOError
        (
            FUNCTION_NAME, __FILE__, __LINE__,
            file, e.startLineNumber(), e.endLineNumber()
        )
            << "Unknown keyword '" << key << "' in "
            << (dict.dictName().empty() ? word("the top level") : dict.dictName())
            << "; expected one of:";
        forAll(known, i)
        {
            FatalIOError << (i ? ", " : " ") << known[i];
        }
        if (known.empty())
        {
            FatalIOError << " none (this block takes no keywords)";
        }
        if (!suggestion.empty())
        {
            FatalIOError << " (did you mean '" << suggestion << "'?)";
        }
        FatalIOError << exit(FatalIOError);
    }
}


Foam::dictionary Foam::diefill::modelCoeffs
(
    const dictionary& couplingDict,
    const word& model
)
{
    const word key(model + "Coeffs");
    const entry* e = couplingDict.findEntry(key, keyType::LITERAL);
    if (e && !e->isDict())
    {
        FatalIOErrorInFunction(couplingDict)
            << key << " is not a dictionary; expected " << key
            << " { ... } with the coefficients of " << model
            << exit(FatalIOError);
    }
    return couplingDict.subOrEmptyDict(key);
}
