#pragma once
// Case-file reader for demLib: OpenFOAM dictionary syntax, parsed without
// OpenFOAM so that DEM-only runs need no fluid solver.  The syntax and every
// error rule are documented in docs/input-format.md.
//
// Strictness contract.  A reader takes what it needs with get/has/subDict/...
// (each call marks the keyword as used and records it as "accepted" for that
// dictionary), then calls checkNoUnusedKeys(): a keyword that no reader asked
// for is a typo or a leftover, and it is reported with a suggestion instead of
// being silently ignored.  Every user error throws dem::InputError whose
// message names the file, the line, the scoped keyword (e.g.
// 'demProperties/materials/sand/youngsModulus') and what was expected.
#include <string>
#include <unordered_map>
#include <vector>

#include "demLib/error.hpp"
#include "demLib/vec3.hpp"

namespace dem {

// The candidate closest to `word` if it is plausibly a typo of it (edit
// distance with adjacent swaps, case-insensitive, at most a third of its
// letters wrong, at least one), else "": the "did you mean" of every keyword
// and value check (also diefillFoam's checkKeywords).
std::string closestWord(const std::string& word, const std::vector<std::string>& candidates);

class Dictionary {
public:
    // An empty dictionary named `scopeName`, read from nowhere.
    explicit Dictionary(std::string scopeName = "dictionary");
    Dictionary(const Dictionary&);
    Dictionary(Dictionary&&) noexcept;
    Dictionary& operator=(const Dictionary&);
    Dictionary& operator=(Dictionary&&) noexcept;
    ~Dictionary();

    // Reads `path`; "#include" paths are relative to the including file.
    // Throws InputError "cannot open ..." if the file is missing, and
    // InputError "<file>:<line>: ..." for any syntax error.
    static Dictionary fromFile(const std::string& path);
    // Parses `text` as if it were the file `sourceName` (used in messages and
    // to resolve relative #include paths).
    static Dictionary fromString(const std::string& text, const std::string& sourceName);

    // --- queries (each marks `key` as used/accepted) -------------------------
    bool has(const std::string& key) const;
    bool isDict(const std::string& key) const;
    // Missing, or not a { } block -> InputError.
    const Dictionary& subDict(const std::string& key) const;

    // Supported T: double, int, long, bool (true/false, on/off, yes/no),
    // std::string (word or quoted string), Vec3 "(x y z)",
    // std::vector<double>, std::vector<int>, std::vector<std::string>,
    // std::vector<Vec3>, std::vector<std::vector<double>>.
    // Missing key or wrong type -> InputError.  Other T fail to link.
    template <class T> T get(const std::string& key) const;
    // Only for keywords documented as optional: `fallback` when absent; when
    // present the value must still have the right type.
    // Write the type for Eigen expressions: getOrDefault<Vec3>("g", Vec3::Zero()).
    template <class T> T getOrDefault(const std::string& key, const T& fallback) const;
    std::string getOrDefault(const std::string& key, const char* fallback) const;

    double getPositive(const std::string& key) const;                         // > 0
    double getNonNegative(const std::string& key) const;                      // >= 0
    double getInRange(const std::string& key, double lo, double hi) const;   // lo <= v <= hi
    // A word from `accepted`; the error lists them and suggests the closest.
    std::string getChoice(const std::string& key, const std::vector<std::string>& accepted) const;

    // Throws one InputError listing every keyword (recursively, in used
    // sub-dictionaries) that no reader asked for, each with file, line,
    // scoped name, "did you mean" and the accepted keywords of its dictionary.
    void checkNoUnusedKeys() const;

    // --- introspection (does not mark keys as used) ---------------------------
    std::vector<std::string> keys() const;   // file order, FoamFile header excluded
    std::string scopedName() const;          // e.g. "demProperties/materials/sand"
    const std::string& fileName() const;     // file this dictionary was opened in
    int lineOf(const std::string& key) const;  // missing key -> InputError
    int line() const;                        // line of the opening '{' (0 for a whole file)
    // "file 'P', line L, keyword 'a/b/c'" (no line when the key is absent),
    // for messages of modules that validate values further.
    std::string describe(const std::string& key) const;

    struct Entry;  // one "key value;" or "key { }" (defined in dictionary.cpp)

private:
    friend class DictionaryParser;

    const Entry* find(const std::string& key) const;
    // Looks `key` up, marks it used and records it as accepted.
    const Entry* query(const std::string& key) const;
    const Entry& require(const std::string& key, const std::string& expected) const;
    void collectUnused(std::vector<std::string>& messages) const;

    std::string scope_;
    std::string file_;
    int line_ = 0;
    std::vector<Entry> entries_;
    std::unordered_map<std::string, std::size_t> index_;
    mutable std::vector<std::string> accepted_;  // queried keys, first-query order
};

}  // namespace dem
