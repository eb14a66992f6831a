#include "checkKeywords.H"
#include "error.H"

#include <algorithm>
#include <vector>

namespace
{

// Levenshtein distance (insertions, deletions, substitutions).
std::size_t editDistance(const std::string& a, const std::string& b)
{
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j)
    {
        row[j] = j;
    }
    for (std::size_t i = 1; i <= a.size(); ++i)
    {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j)
        {
            const std::size_t above = row[j];
            row[j] = std::min
            ({
                row[j] + 1,
                row[j - 1] + 1,
                diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)
            });
            diagonal = above;
        }
    }
    return row[b.size()];
}

} // End anonymous namespace


Foam::word Foam::diefill::closestWord
(
    const word& misspelt,
    const wordList& accepted
)
{
    const std::size_t limit = std::max<std::size_t>(2, misspelt.size()/3);
    word best;
    std::size_t bestDistance = limit + 1;
    for (const word& w : accepted)
    {
        const std::size_t d = editDistance(misspelt, w);
        if (d < bestDistance)
        {
            best = w;
            bestDistance = d;
        }
    }
    return best;
}


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
        const word suggestion = closestWord(key, known);
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
