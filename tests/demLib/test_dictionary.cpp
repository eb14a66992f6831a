// Tests of dem::Dictionary: every value kind is parsed to the right numbers,
// and every user error throws InputError whose message names the file, the
// line, the scoped keyword and what was expected.
#include "demLib/dictionary.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#ifndef DEMLIB_TEST_DATA_DIR
#error "DEMLIB_TEST_DATA_DIR must point to tests/demLib/data"
#endif

namespace {

using dem::Dictionary;
using dem::InputError;
using dem::Vec3;

const std::string dataDir = std::string(DEMLIB_TEST_DATA_DIR) + "/dictionary";

// Runs `action`, requires an InputError, and requires every fragment in its
// message; returns the message for further checks.
std::string expectInputError(const std::function<void()>& action, const std::vector<std::string>& fragments) {
    try {
        action();
    } catch (const InputError& e) {
        const std::string message = e.what();
        for (const auto& fragment : fragments)
            EXPECT_NE(message.find(fragment), std::string::npos)
                << "message lacks \"" << fragment << "\"\nmessage: " << message;
        return message;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected dem::InputError, got another exception: " << e.what();
        return "";
    }
    ADD_FAILURE() << "expected dem::InputError, nothing was thrown";
    return "";
}

Dictionary parse(const std::string& text) { return Dictionary::fromString(text, "constant/demProperties"); }

// ------------------------------------------------------------ value kinds
TEST(Dictionary, ParsesScalarValueKinds) {
    const Dictionary d = parse(
        "density 2500;\n"
        "youngsModulus -5.5e6;\n"
        "small +.25E-3;\n"
        "nParticles 12000;\n"
        "bigCount 1e5;\n"
        "seed 9000000000;\n"
        "useGravity on;\n"
        "writeVtk no;\n"
        "restart true;\n"
        "model epsd2;\n"
        "title \"die \\\"fill\\\" {test}; (a)\";\n"
        "alloy 316L;\n");
    EXPECT_DOUBLE_EQ(d.get<double>("density"), 2500.0);
    EXPECT_DOUBLE_EQ(d.get<double>("youngsModulus"), -5.5e6);
    EXPECT_DOUBLE_EQ(d.get<double>("small"), 0.25e-3);
    EXPECT_EQ(d.get<int>("nParticles"), 12000);
    EXPECT_EQ(d.get<int>("bigCount"), 100000);
    EXPECT_EQ(d.get<long>("seed"), 9000000000L);
    EXPECT_TRUE(d.get<bool>("useGravity"));
    EXPECT_FALSE(d.get<bool>("writeVtk"));
    EXPECT_TRUE(d.get<bool>("restart"));
    EXPECT_EQ(d.get<std::string>("model"), "epsd2");
    EXPECT_EQ(d.get<std::string>("title"), "die \"fill\" {test}; (a)");
    EXPECT_EQ(d.get<std::string>("alloy"), "316L");
    EXPECT_EQ(d.get<long>("nParticles"), 12000L);
    EXPECT_NO_THROW(d.checkNoUnusedKeys());
}

TEST(Dictionary, ParsesListsOfNumbersWordsAndVectors) {
    const Dictionary d = parse(
        "gravity (0 0 -9.81);\n"
        "radii (1e-4 2e-4 3.5e-4);\n"
        "counts (3 1 4 1 5);\n"
        "names (sand glass \"steel ball\");\n"
        "empty ();\n"
        "box\n"
        "(\n"
        "    (0 0 0)\n"
        "    (0.04 0.02 0.01)\n"
        ");\n"
        "table ((0 1) (0.5 2 3) ());\n");
    const Vec3 g = d.get<Vec3>("gravity");
    EXPECT_DOUBLE_EQ(g.x(), 0.0);
    EXPECT_DOUBLE_EQ(g.y(), 0.0);
    EXPECT_DOUBLE_EQ(g.z(), -9.81);
    EXPECT_EQ(d.get<std::vector<double>>("radii"), (std::vector<double>{1e-4, 2e-4, 3.5e-4}));
    EXPECT_EQ(d.get<std::vector<int>>("counts"), (std::vector<int>{3, 1, 4, 1, 5}));
    EXPECT_EQ(d.get<std::vector<std::string>>("names"), (std::vector<std::string>{"sand", "glass", "steel ball"}));
    EXPECT_TRUE(d.get<std::vector<double>>("empty").empty());
    const auto box = d.get<std::vector<Vec3>>("box");
    ASSERT_EQ(box.size(), 2u);
    EXPECT_DOUBLE_EQ((box[1] - box[0]).norm(), std::sqrt(0.04 * 0.04 + 0.02 * 0.02 + 0.01 * 0.01));
    const auto table = d.get<std::vector<std::vector<double>>>("table");
    ASSERT_EQ(table.size(), 3u);
    EXPECT_EQ(table[0], (std::vector<double>{0.0, 1.0}));
    EXPECT_EQ(table[1], (std::vector<double>{0.5, 2.0, 3.0}));
    EXPECT_TRUE(table[2].empty());
    EXPECT_EQ(d.lineOf("box"), 6);
}

TEST(Dictionary, NestedDictionariesKeepOrderScopeAndLines) {
    const Dictionary d = parse(
        "materials\n"
        "{\n"
        "    sand\n"
        "    {\n"
        "        youngsModulus 5e6;\n"
        "        density 2500;\n"
        "    }\n"
        "    glass { density 2200; }\n"
        "}\n"
        "zeta 1;\n"
        "alpha 2;\n");
    EXPECT_EQ(d.keys(), (std::vector<std::string>{"materials", "zeta", "alpha"}));
    EXPECT_TRUE(d.isDict("materials"));
    EXPECT_FALSE(d.isDict("zeta"));
    const Dictionary& sand = d.subDict("materials").subDict("sand");
    EXPECT_EQ(sand.scopedName(), "demProperties/materials/sand");
    EXPECT_EQ(sand.keys(), (std::vector<std::string>{"youngsModulus", "density"}));
    EXPECT_EQ(sand.fileName(), "constant/demProperties");
    EXPECT_EQ(sand.line(), 4);
    EXPECT_EQ(sand.lineOf("density"), 6);
    EXPECT_DOUBLE_EQ(sand.get<double>("youngsModulus"), 5e6);
    EXPECT_DOUBLE_EQ(d.subDict("materials").subDict("glass").get<double>("density"), 2200.0);
    EXPECT_EQ(sand.describe("density"),
              "file 'constant/demProperties', line 6, keyword 'demProperties/materials/sand/density'");
    EXPECT_EQ(sand.describe("poissonsRatio"), "file 'constant/demProperties', keyword 'demProperties/materials/sand/poissonsRatio'");
}

TEST(Dictionary, CommentsDimensionsAndHeaderAreIgnored) {
    const Dictionary d = parse(
        "FoamFile { version 2.0; format ascii; class dictionary; object demProperties; }\n"
        "/* a block comment\n"
        "   over two lines with ; { ( */\n"
        "nu [0 2 -1 0 0 0 0] 1.5e-5; // trailing comment with ; and }\n"
        "list (1 /* inside */ 2 // to end of line\n"
        "      3);\n"
        "word abc/*glued*/;\n"
        "path a/b/c;\n");
    EXPECT_EQ(d.keys(), (std::vector<std::string>{"nu", "list", "word", "path"}));
    EXPECT_FALSE(d.has("FoamFile"));
    EXPECT_DOUBLE_EQ(d.get<double>("nu"), 1.5e-5);
    EXPECT_EQ(d.lineOf("nu"), 4);
    EXPECT_EQ(d.get<std::vector<double>>("list"), (std::vector<double>{1, 2, 3}));
    EXPECT_EQ(d.lineOf("list"), 5);
    EXPECT_EQ(d.get<std::string>("word"), "abc");
    EXPECT_EQ(d.get<std::string>("path"), "a/b/c");
    EXPECT_NO_THROW(d.checkNoUnusedKeys());
}

TEST(Dictionary, SubstitutesScalarsFromSameOrEnclosingDictionary) {
    const Dictionary d = parse(
        "d 0.002;\n"
        "rho 2500;\n"
        "particles\n"
        "{\n"
        "    diameter $d;\n"
        "    sizes ($d 0.003);\n"
        "    inner { density $rho; copy $density; }\n"
        "    density 1000;\n"
        "    again $density;\n"
        "}\n");
    const Dictionary& p = d.subDict("particles");
    EXPECT_DOUBLE_EQ(p.get<double>("diameter"), 0.002);
    EXPECT_EQ(p.get<std::vector<double>>("sizes"), (std::vector<double>{0.002, 0.003}));
    // 'copy' sees the inner 'density' (2500), not the later outer one (1000).
    EXPECT_DOUBLE_EQ(p.subDict("inner").get<double>("copy"), 2500.0);
    EXPECT_DOUBLE_EQ(p.subDict("inner").get<double>("density"), 2500.0);
    EXPECT_DOUBLE_EQ(p.get<double>("again"), 1000.0);
    EXPECT_DOUBLE_EQ(p.get<double>("density"), 1000.0);
    // d and rho were only referenced: that is a use, not an unknown keyword.
    EXPECT_NO_THROW(d.checkNoUnusedKeys());

    expectInputError([] { parse("a 1;\nsub\n{\n  b $c;\n}\nc 2;\n"); },
                     {"constant/demProperties:4:", "'$c' is not defined", "demProperties/sub"});
    expectInputError([] { parse("s { x 1; }\ny $s;\n"); }, {"constant/demProperties:2:", "'$s' refers to a sub-dictionary"});
}

// ------------------------------------------------------------ includes
TEST(Dictionary, ReadsIncludesRelativeToTheIncludingFile) {
    const std::string path = dataDir + "/demProperties";
    const Dictionary d = Dictionary::fromFile(path);
    EXPECT_EQ(d.scopedName(), "demProperties");
    EXPECT_EQ(d.keys(), (std::vector<std::string>{"rollingModel", "gravity", "materials", "interactions"}));
    EXPECT_EQ(d.getChoice("rollingModel", {"none", "cdt", "epsd", "epsd2"}), "epsd2");
    EXPECT_DOUBLE_EQ(d.get<Vec3>("gravity").z(), -9.81);

    const Dictionary& sand = d.subDict("materials").subDict("sand");
    EXPECT_DOUBLE_EQ(sand.getPositive("density"), 2500.0);
    EXPECT_DOUBLE_EQ(sand.getPositive("youngsModulus"), 5e6);
    EXPECT_DOUBLE_EQ(sand.getInRange("poissonsRatio", 0.0, 0.5), 0.3);
    // Entries remember the file they were written in.
    EXPECT_EQ(sand.fileName(), dataDir + "/materials/sand.inc");
    EXPECT_EQ(sand.lineOf("youngsModulus"), 2);
    EXPECT_EQ(sand.describe("youngsModulus"), "file '" + dataDir + "/materials/sandStiffness.inc', line 2, keyword "
                                              "'demProperties/materials/sand/youngsModulus'");

    const Dictionary& ss = d.subDict("interactions").subDict("sand-sand");
    EXPECT_EQ(ss.scopedName(), "demProperties/interactions/sand-sand");
    EXPECT_DOUBLE_EQ(ss.get<double>("friction"), 0.5);
    EXPECT_DOUBLE_EQ(ss.get<double>("rollingFriction"), 0.1);
    EXPECT_DOUBLE_EQ(ss.get<double>("restitution"), 0.6);
    EXPECT_EQ(ss.lineOf("restitution"), 5);
    EXPECT_NO_THROW(d.checkNoUnusedKeys());
}

TEST(Dictionary, IncludeErrorsNameTheRightFileAndLine) {
    const std::string main = dataDir + "/main";
    expectInputError([&] { Dictionary::fromString("a 1;\n\n#include \"noSuchFile.inc\"\n", main); },
                     {main + ":3:", "cannot open included file 'noSuchFile.inc'", dataDir + "/noSuchFile.inc"});
    expectInputError([&] { Dictionary::fromString("x { #include \"brokenInclude.inc\" }\n", main); },
                     {dataDir + "/brokenInclude.inc:4:", "expected ';' after value of 'restitution'", "got 'rollingFriction'",
                      "on line 5"});
    expectInputError([&] { Dictionary::fromString("#include \"cycleA.inc\"\n", main); },
                     {dataDir + "/cycleB.inc:2:", "includes itself", "cycleA.inc -> ", "cycleB.inc -> "});
    expectInputError([&] { Dictionary::fromString("#include noQuotes\n", main); },
                     {main + ":1:", "expected a quoted file name after #include"});
    expectInputError([&] { Dictionary::fromString("#includeEtc \"caseDicts/x\"\n", main); },
                     {main + ":1:", "unsupported directive '#includeEtc'"});
    // Duplicates across files name both places.
    expectInputError([&] { Dictionary::fromString("friction 0.4;\n#include \"interactions.inc\"\nsand-sand 1;\n", main); },
                     {main + ":3:", "duplicate keyword 'main/sand-sand'", dataDir + "/interactions.inc:1"});
}

TEST(Dictionary, MissingFileIsAnInputError) {
    expectInputError([] { Dictionary::fromFile("/nonexistent/constant/demProperties"); },
                     {"cannot open", "/nonexistent/constant/demProperties"});
    expectInputError([] { Dictionary::fromFile(dataDir); }, {"cannot open", dataDir});  // a directory
}

// ------------------------------------------------------------ syntax errors
TEST(Dictionary, SyntaxErrorsNameFileLineAndWhatWasExpected) {
    const std::string f = "constant/demProperties";
    expectInputError([] { parse("a 1;\ndensity 2500\nb 2;\n"); },
                     {f + ":2:", "expected ';' after value of 'density'", "got 'b' on line 3"});
    expectInputError([] { parse("a 1;\nmaterials\n{\n  sand\n  {\n    density 1;\n  }\n"); },
                     {f + ":3:", "unbalanced '{'", "demProperties/materials", "not closed"});
    expectInputError([] { parse("a 1;\n}\n"); }, {f + ":2:", "unexpected '}'"});
    expectInputError([] { parse("a 1;\nbox ((0 0 0)\n  (1 1 1);\n"); },
                     {f + ":3:", "unbalanced '('", "'box'", "opened on line 2", "before ';'"});
    expectInputError([] { parse("a 1;\nb (1 2 3)\n"); }, {f + ":2:", "expected ';' after value of 'b', got the end of the file"});
    expectInputError([] { parse("a 1;\n/* open\n\nb 2;\n"); }, {f + ":2:", "unterminated comment"});
    expectInputError([] { parse("a 1;\ntitle \"no end;\nb 2;\n"); }, {f + ":2:", "unterminated string"});
    expectInputError([] { parse("a 1;\nrho ;\n"); }, {f + ":2:", "expected a value after keyword 'rho'", "got ';'"});
    expectInputError([] { parse("a 1;\n0.5 2;\n"); }, {f + ":2:", "expected a keyword in 'demProperties'", "got '0.5'"});
    expectInputError([] { parse("nu [0 2 -1 0 0 0 0 1e-5;\n"); }, {f + ":1:", "unbalanced '['", "'nu'"});
    expectInputError([] { parse("a 1;\nb $;\n"); }, {f + ":2:", "'$' must be followed by a name"});
    expectInputError([] { parse("x 1;\ns\n{\n  y 1;\n  y 2;\n}\n"); },
                     {f + ":5:", "duplicate keyword 'demProperties/s/y'", f + ":4"});
    expectInputError([] { parse("a 1;\n\"quoted\" 2;\n"); }, {f + ":2:", "expected a keyword", "got '\"quoted\"'"});
    expectInputError([] { parse("a (1 #include \"x\");\n"); }, {f + ":1:", "unbalanced '('", "before '#include'"});
    // Runaway nesting is an error with a line, not a stack overflow.
    expectInputError([] { parse("a\n" + std::string(100000, '(') + ";\n"); }, {f + ":2:", "nested more than 256"});
}

// ------------------------------------------------------------ type errors
TEST(Dictionary, WrongTypesAndMissingKeysSayWhatWasExpected) {
    const std::string f = "constant/demProperties";
    const Dictionary d = parse(
        "materials\n{\n  sand\n  {\n"
        "    density dense;\n"          // line 5
        "    count 2.5;\n"              // line 6
        "    useCohesion maybe;\n"      // line 7
        "    gravity (0 -9.81);\n"      // line 8
        "    radii (1e-4 big 3e-4);\n"  // line 9
        "    huge 1e400;\n"             // line 10
        "    name (a b);\n"             // line 11
        "    scalar 3;\n"               // line 12
        "  }\n}\n");
    const Dictionary& sand = d.subDict("materials").subDict("sand");
    const std::string k = "keyword 'demProperties/materials/sand/";
    expectInputError([&] { sand.get<double>("density"); }, {f + ":5:", k + "density'", "expected a number", "got 'dense'"});
    expectInputError([&] { sand.get<int>("count"); }, {f + ":6:", k + "count'", "expected an integer", "got '2.5'"});
    expectInputError([&] { sand.get<bool>("useCohesion"); },
                     {f + ":7:", k + "useCohesion'", "true/false, on/off, yes/no", "got 'maybe'"});
    expectInputError([&] { sand.get<Vec3>("gravity"); }, {f + ":8:", k + "gravity'", "3 numbers", "(2 items)"});
    expectInputError([&] { sand.get<std::vector<double>>("radii"); },
                     {f + ":9:", k + "radii'", "list of numbers", "item 2 is 'big'"});
    expectInputError([&] { sand.get<double>("huge"); }, {f + ":10:", k + "huge'", "outside the range"});
    expectInputError([&] { sand.get<int>("huge"); }, {f + ":10:", k + "huge'", "expected an integer"});
    expectInputError([&] { sand.get<std::string>("name"); }, {f + ":11:", k + "name'", "expected a word", "got '(a b)'"});
    expectInputError([&] { sand.get<std::vector<double>>("scalar"); }, {f + ":12:", k + "scalar'", "list of numbers", "got '3'"});
    expectInputError([&] { d.get<double>("materials"); }, {f + ":1:", "'demProperties/materials'", "got a sub-dictionary"});
    // Missing: the file, the line of the enclosing block, the scoped key and the expected type.
    expectInputError([&] { sand.get<double>("poissonsRatio"); },
                     {f + ":4:", k + "poissonsRatio' is missing", "expected a number"});
    expectInputError([&] { d.get<Vec3>("gravity"); }, {f + ": keyword 'demProperties/gravity' is missing", "(x y z)"});
    expectInputError([&] { d.subDict("solver"); }, {"'demProperties/solver' is missing", "sub-dictionary"});
    expectInputError([&] { sand.subDict("scalar"); }, {f + ":12:", k + "scalar'", "expected a sub-dictionary", "got '3'"});
    expectInputError([&] { sand.lineOf("absent"); }, {k + "absent' is missing"});
}

TEST(Dictionary, RangeChecksRejectOutOfRangeValues) {
    const std::string f = "constant/demProperties";
    const Dictionary d = parse(
        "materials { sand {\n"
        "  youngsModulus -5e6;\n"
        "  zero 0;\n"
        "  ratio 0.5;\n"
        "  big 1.0000001;\n"
        "  word soft;\n"
        "} }\n");
    const Dictionary& sand = d.subDict("materials").subDict("sand");
    const std::string k = "keyword 'demProperties/materials/sand/";
    expectInputError([&] { sand.getPositive("youngsModulus"); },
                     {f + ":2:", k + "youngsModulus'", "expected a positive number", "got '-5e6'"});
    expectInputError([&] { sand.getPositive("zero"); }, {f + ":3:", k + "zero'", "positive"});
    EXPECT_DOUBLE_EQ(sand.getNonNegative("zero"), 0.0);
    expectInputError([&] { sand.getNonNegative("youngsModulus"); }, {f + ":2:", "non-negative", "got '-5e6'"});
    EXPECT_DOUBLE_EQ(sand.getInRange("ratio", 0.0, 0.5), 0.5);  // inclusive upper end
    EXPECT_DOUBLE_EQ(sand.getInRange("zero", 0.0, 0.5), 0.0);   // inclusive lower end
    expectInputError([&] { sand.getInRange("big", 0.0, 1.0); }, {f + ":5:", k + "big'", "in [0, 1]", "got '1.0000001'"});
    expectInputError([&] { sand.getPositive("word"); }, {f + ":6:", "positive", "got 'soft'"});
    expectInputError([&] { sand.getInRange("missing", 0.0, 0.5); }, {k + "missing' is missing", "in [0, 0.5]"});
}

TEST(Dictionary, ChoicesListAcceptedValuesAndSuggestTheClosest) {
    const std::string f = "constant/demProperties";
    const std::vector<std::string> models{"none", "cdt", "epsd", "epsd2"};
    const Dictionary d = parse("a 1;\nrollingModel epsd3;\ncohesion (capillary);\nfluid \"none\";\n");
    expectInputError([&] { d.getChoice("rollingModel", models); },
                     {f + ":2:", "keyword 'demProperties/rollingModel'", "unknown value 'epsd3'",
                      "expected one of: none, cdt, epsd, epsd2", "(did you mean 'epsd2'?)"});
    const std::string far = expectInputError([&] { d.getChoice("rollingModel", {"linear", "hertz"}); }, {"one of: linear, hertz"});
    EXPECT_EQ(far.find("did you mean"), std::string::npos) << "no suggestion for an unrelated word: " << far;
    expectInputError([&] { d.getChoice("cohesion", {"none", "capillary"}); },
                     {f + ":3:", "expected one of: none, capillary", "got '(capillary)'"});
    expectInputError([&] { d.getChoice("contactModel", models); },
                     {f + ": keyword 'demProperties/contactModel' is missing; expected one of: none, cdt, epsd, epsd2"});
    EXPECT_EQ(d.getChoice("fluid", {"none", "openfoam"}), "none");
}

// ------------------------------------------------------------ strictness
TEST(Dictionary, UnusedKeywordIsReportedWithSuggestionAndAcceptedList) {
    const std::string f = "constant/demProperties";
    const Dictionary d = parse(
        "interactions\n"
        "{\n"
        "    sand-sand\n"
        "    {\n"
        "        friction 0.5;\n"
        "        rollingFrction 0.1;\n"  // line 6: misspelt
        "        restitution 0.6;\n"
        "    }\n"
        "}\n"
        "timeStep 1e-6;\n");
    const Dictionary& ss = d.subDict("interactions").subDict("sand-sand");
    EXPECT_DOUBLE_EQ(ss.get<double>("friction"), 0.5);
    EXPECT_DOUBLE_EQ(ss.getOrDefault("rollingFriction", 0.0), 0.0);  // optional: absent -> fallback
    EXPECT_DOUBLE_EQ(ss.get<double>("restitution"), 0.6);
    EXPECT_DOUBLE_EQ(d.get<double>("timeStep"), 1e-6);
    expectInputError([&] { d.checkNoUnusedKeys(); },
                     {f + ":6:", "unknown keyword 'rollingFrction' in 'demProperties/interactions/sand-sand'",
                      "did you mean 'rollingFriction'?", "Accepted: friction, rollingFriction, restitution"});
}

TEST(Dictionary, UnusedCheckIsRecursiveAndListsEveryUnknownKey) {
    const std::string f = "constant/demProperties";
    const Dictionary d = parse(
        "Density 2500;\n"                  // line 1: case typo of 'density'
        "density2 1;\n"                    // line 2
        "solver { nIter 3; tolerance 1e-6; }\n"
        "outputs { vtk on; }\n"           // line 4: never read at all
        "zzz 1;\n");                       // line 5: nothing close
    d.getOrDefault("density", 1.0);
    EXPECT_EQ(d.subDict("solver").get<int>("nIter"), 3);
    const std::string message = expectInputError(
        [&] { d.checkNoUnusedKeys(); },
        {f + ":1: unknown keyword 'Density' in 'demProperties'; did you mean 'density'? Accepted: density, solver",
         f + ":2: unknown keyword 'density2'", f + ":3: unknown keyword 'tolerance' in 'demProperties/solver'",
         "Accepted: nIter", f + ":4: unknown keyword 'outputs'", f + ":5: unknown keyword 'zzz'"});
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 4) << message;
    EXPECT_EQ(message.find("did you mean 'solver'"), std::string::npos) << message;
    // A dictionary nobody reads from says so instead of an empty list.
    const Dictionary unread = parse("x 1;\n");
    expectInputError([&] { unread.checkNoUnusedKeys(); }, {f + ":1:", "no keywords are read from 'demProperties'"});
}

TEST(Dictionary, OptionalKeywordsUseFallbackButStillCheckTheType) {
    const Dictionary d = parse("writeInterval 5;\nformat binary;\nflag 3;\n");
    EXPECT_EQ(d.getOrDefault("writeInterval", 1), 5);
    EXPECT_EQ(d.getOrDefault("nThreads", 4), 4);
    EXPECT_EQ(d.getOrDefault("format", "ascii"), "binary");
    EXPECT_EQ(d.getOrDefault("name", "die"), "die");
    const Vec3 g = d.getOrDefault<Vec3>("gravity", Vec3(0, 0, -9.81));
    EXPECT_DOUBLE_EQ(g.z(), -9.81);
    expectInputError([&] { d.getOrDefault("flag", false); }, {"constant/demProperties:3:", "'demProperties/flag'", "switch"});
    EXPECT_NO_THROW(d.checkNoUnusedKeys());
}

TEST(Dictionary, IntegersAreExactAndRangeChecked) {
    const Dictionary d = parse("exact 9007199254740993;\nbeyondInt 3000000000;\nnegative -2147483648;\nbeyondLong 1e19;\n");
    EXPECT_EQ(d.get<long>("exact"), 9007199254740993L);  // 2^53 + 1: not representable as a double
    EXPECT_EQ(d.get<long>("beyondInt"), 3000000000L);
    EXPECT_EQ(d.get<int>("negative"), -2147483647 - 1);
    expectInputError([&] { d.get<int>("beyondInt"); }, {"constant/demProperties:2:", "'demProperties/beyondInt'", "32-bit"});
    expectInputError([&] { d.get<long>("beyondLong"); }, {"constant/demProperties:4:", "64-bit"});
}

TEST(Dictionary, ParsesSeveralThousandLinesQuickly) {
    std::string text = "FoamFile { version 2.0; }\nparticles\n{\n";
    const int n = 4000;
    for (int i = 0; i < n; ++i)
        text += "    p" + std::to_string(i) + " (" + std::to_string(i) + " " + std::to_string(0.5 * i) + " -1e-3); // #" +
                std::to_string(i) + "\n";
    text += "}\n";
    const auto start = std::chrono::steady_clock::now();
    const Dictionary d = Dictionary::fromString(text, "bulk");
    const Dictionary& p = d.subDict("particles");
    double sumY = 0.0;
    for (const auto& key : p.keys()) sumY += p.get<Vec3>(key).y();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(p.keys().size(), static_cast<std::size_t>(n));
    EXPECT_DOUBLE_EQ(sumY, 0.5 * n * (n - 1) / 2.0);  // 0.5 * sum of 0..n-1
    EXPECT_EQ(p.lineOf("p3999"), 3 + n);
    EXPECT_LT(seconds, 2.0) << "4000 entries took " << seconds << " s";
    EXPECT_NO_THROW(d.checkNoUnusedKeys());
}

}  // namespace
