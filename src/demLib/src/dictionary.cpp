#include "demLib/dictionary.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace dem {

// A parsed value.  Scalars keep their source text so that messages can quote
// exactly what the user wrote ("got '-5e6'").
struct Dictionary::Entry {
    struct Value {
        enum class Kind { Word, Number, String, List, Dict };
        Kind kind = Kind::Word;
        std::string text;                 // Word/Number/String (unescaped)
        std::vector<Value> items;         // List
        std::optional<Dictionary> dict;   // Dict
    };
    std::string name;
    std::string file;
    int line = 0;
    Value value;
    mutable bool used = false;
};

using Value = Dictionary::Entry::Value;

namespace {

// "file:line: " or "file: " when the line is unknown.
std::string at(const std::string& file, int line) {
    return line > 0 ? file + ":" + std::to_string(line) + ": " : file + ": ";
}

std::string join(const std::vector<std::string>& words, const std::string& separator = ", ") {
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) out += (i ? separator : "") + words[i];
    return out;
}

std::string formatNumber(double v) {
    std::ostringstream os;
    os.precision(12);
    os << v;
    return os.str();
}

// Optimal-string-alignment distance (Levenshtein plus adjacent swaps), case
// insensitive: "rollingFrction" -> "rollingFriction" is 1, "Denisty" -> "density" 1.
std::size_t editDistance(const std::string& a, const std::string& b) {
    auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
    const std::size_t n = a.size(), m = b.size();
    std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
    for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= n; ++i)
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]))
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[n][m];
}


// ---------------------------------------------------------------- tokenizer
enum class TokenKind {
    Word, Number, String, Variable, Directive,
    LBrace, RBrace, LParen, RParen, LBracket, RBracket, Semicolon, End
};

struct Token {
    TokenKind kind;
    std::string text;
    int line;
};

// A token as the user wrote it, quoted for messages.
std::string shown(const Token& t) {
    switch (t.kind) {
        case TokenKind::String: return "'\"" + t.text + "\"'";
        case TokenKind::Variable: return "'$" + t.text + "'";
        case TokenKind::Directive: return "'#" + t.text + "'";
        case TokenKind::End: return "the end of the file";
        default: return "'" + t.text + "'";
    }
}

bool isPunctuation(char c) {
    return c == '{' || c == '}' || c == '(' || c == ')' || c == '[' || c == ']' || c == ';' || c == '"';
}

// [+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?  -- no inf/nan/hex.
bool looksLikeNumber(const std::string& s) {
    std::size_t i = 0;
    auto digits = [&] { std::size_t start = i; while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i; return i - start; };
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    std::size_t mantissa = digits();
    if (i < s.size() && s[i] == '.') { ++i; mantissa += digits(); }
    if (mantissa == 0) return false;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
        if (digits() == 0) return false;
    }
    return i == s.size();
}

std::vector<Token> tokenize(const std::string& text, const std::string& file) {
    std::vector<Token> tokens;
    std::size_t i = 0;
    int line = 1;
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;  // UTF-8 byte-order mark
    const std::size_t n = text.size();
    auto startsComment = [&](std::size_t k) { return k + 1 < n && text[k] == '/' && (text[k + 1] == '/' || text[k + 1] == '*'); };
    auto readWord = [&] {
        const std::size_t start = i;
        while (i < n && !std::isspace(static_cast<unsigned char>(text[i])) && !isPunctuation(text[i]) && !startsComment(i)) ++i;
        return text.substr(start, i - start);
    };
    while (i < n) {
        const char c = text[i];
        if (c == '\n') { ++line; ++i; continue; }
        if (std::isspace(static_cast<unsigned char>(c))) { ++i; continue; }
        if (c == '/' && i + 1 < n && text[i + 1] == '/') {
            while (i < n && text[i] != '\n') ++i;
            continue;
        }
        if (c == '/' && i + 1 < n && text[i + 1] == '*') {
            const int openLine = line;
            const std::size_t close = text.find("*/", i + 2);
            if (close == std::string::npos)
                throw InputError(at(file, openLine) + "unterminated comment: '/*' opened here has no closing '*/'");
            line += static_cast<int>(std::count(text.begin() + static_cast<long>(i), text.begin() + static_cast<long>(close), '\n'));
            i = close + 2;
            continue;
        }
        if (c == '"') {
            const int openLine = line;
            std::string value;
            ++i;
            while (i < n && text[i] != '"') {
                if (text[i] == '\\' && i + 1 < n && (text[i + 1] == '"' || text[i + 1] == '\\')) ++i;
                if (text[i] == '\n') ++line;
                value += text[i++];
            }
            if (i >= n) throw InputError(at(file, openLine) + "unterminated string: '\"' opened here has no closing '\"'");
            ++i;
            tokens.push_back({TokenKind::String, value, openLine});
            continue;
        }
        switch (c) {
            case '{': tokens.push_back({TokenKind::LBrace, "{", line}); ++i; continue;
            case '}': tokens.push_back({TokenKind::RBrace, "}", line}); ++i; continue;
            case '(': tokens.push_back({TokenKind::LParen, "(", line}); ++i; continue;
            case ')': tokens.push_back({TokenKind::RParen, ")", line}); ++i; continue;
            case '[': tokens.push_back({TokenKind::LBracket, "[", line}); ++i; continue;
            case ']': tokens.push_back({TokenKind::RBracket, "]", line}); ++i; continue;
            case ';': tokens.push_back({TokenKind::Semicolon, ";", line}); ++i; continue;
            default: break;
        }
        if (c == '#' || c == '$') {
            ++i;
            const std::string name = readWord();
            if (name.empty())
                throw InputError(at(file, line) + "'" + std::string(1, c) + "' must be followed by a name");
            tokens.push_back({c == '#' ? TokenKind::Directive : TokenKind::Variable, name, line});
            continue;
        }
        std::string word = readWord();
        tokens.push_back({looksLikeNumber(word) ? TokenKind::Number : TokenKind::Word, std::move(word), line});
    }
    tokens.push_back({TokenKind::End, "end of file", line});
    return tokens;
}

std::string readFile(const std::string& path, bool& ok) {
    // Checked before opening: opening a FIFO waits for a writer, reading a device never ends.
    ok = std::filesystem::is_regular_file(path);
    if (!ok) return "";
    std::ifstream in(path, std::ios::binary);
    ok = in.good();
    if (!ok) return "";
    std::ostringstream buffer;
    buffer << in.rdbuf();
    return buffer.str();
}

// ------------------------------------------------------------ value display
std::string show(const Value& v) {
    switch (v.kind) {
        case Value::Kind::Word:
        case Value::Kind::Number: return v.text;
        case Value::Kind::String: return "\"" + v.text + "\"";
        case Value::Kind::Dict: return "{ ... }";
        case Value::Kind::List: {
            std::string out = "(";
            for (std::size_t i = 0; i < v.items.size() && out.size() < 60; ++i) out += (i ? " " : "") + show(v.items[i]);
            if (out.size() >= 60) out = out.substr(0, 57) + "...";
            return out + ")";
        }
    }
    return "";
}

std::string quoteShown(const Value& v) {
    return v.kind == Value::Kind::Dict ? "a sub-dictionary { ... }" : "'" + show(v) + "'";
}

}  // namespace

// The closest candidate if it is plausibly a typo of `word` (at most a third
// of its letters wrong, at least one allowed), else "".  Ties go to the
// candidate of the same length ("epsd3" -> "epsd2", not "epsd").
std::string closestWord(const std::string& word, const std::vector<std::string>& candidates) {
    auto lengthGap = [&](const std::string& c) { return c.size() > word.size() ? c.size() - word.size() : word.size() - c.size(); };
    std::string best;
    std::size_t bestDistance = std::numeric_limits<std::size_t>::max();
    for (const auto& c : candidates) {
        const std::size_t d = editDistance(word, c);
        if (d < bestDistance || (d == bestDistance && lengthGap(c) < lengthGap(best))) { bestDistance = d; best = c; }
    }
    if (best.empty()) return "";
    const std::size_t allowed = std::max<std::size_t>(1, std::max(word.size(), best.size()) / 3);
    return bestDistance <= allowed ? best : "";
}

// ------------------------------------------------------------------- parser
// Recursive descent over the tokens of one file; "#include" starts a parser
// on the included file that adds its entries to the current dictionary.
class DictionaryParser {
public:
    DictionaryParser(std::vector<Token> tokens, std::string file, std::vector<std::string>& includeStack, int depth = 0)
        : tokens_(std::move(tokens)), file_(std::move(file)), includeStack_(includeStack), depth_(depth) {}

    // Parses entries into scopes.back() until '}' (a block) or end of file.
    // `scopes` holds the enclosing dictionaries, for $name look-ups.
    void parseBody(std::vector<Dictionary*>& scopes, bool wholeFile) {
        Dictionary& target = *scopes.back();
        for (;;) {
            const Token& t = peek();
            switch (t.kind) {
                case TokenKind::End:
                    if (wholeFile) return;
                    fail(target.line_, "unbalanced '{': the block of '" + target.scope_ +
                                           "' opened here is not closed by '}' before the end of the file");
                case TokenKind::RBrace:
                    if (wholeFile) fail(t.line, "unexpected '}' with no matching '{'");
                    ++pos_;
                    return;
                case TokenKind::Directive: parseDirective(scopes); break;
                case TokenKind::Word: parseEntry(scopes, wholeFile); break;
                default:
                    fail(t.line, "expected a keyword in '" + target.scope_ + "', got " + shown(t));
            }
        }
    }

private:
    const Token& peek() const { return tokens_[pos_]; }
    const Token& next() { return tokens_[pos_ < tokens_.size() - 1 ? pos_++ : pos_]; }
    [[noreturn]] void fail(int line, const std::string& what) const { throw InputError(at(file_, line) + what); }

    // Recursion guard: a runaway "((((..." must be an error, not a stack overflow.
    static constexpr int maxDepth = 256;
    void enter(int line) {
        if (++depth_ > maxDepth)
            fail(line, "blocks and lists are nested more than " + std::to_string(maxDepth) + " levels deep");
    }

    void parseDirective(std::vector<Dictionary*>& scopes) {
        const Token directive = next();
        if (directive.text != "include")
            fail(directive.line, "unsupported directive '#" + directive.text + "'; only #include \"file\" is supported");
        const Token& name = next();
        if (name.kind != TokenKind::String)
            fail(directive.line, "expected a quoted file name after #include, got " + shown(name));
        std::filesystem::path path(name.text);
        if (path.is_relative()) path = std::filesystem::path(file_).parent_path() / path;
        const std::string resolved = path.lexically_normal().string();
        for (const auto& open : includeStack_)
            if (std::filesystem::path(open).lexically_normal() == path.lexically_normal())
                fail(directive.line, "#include \"" + name.text + "\" includes itself (include chain: " +
                                         join(includeStack_, " -> ") + " -> " + resolved + ")");
        bool ok = false;
        const std::string text = readFile(resolved, ok);
        if (!ok) fail(directive.line, "cannot open included file '" + name.text + "' (looked for '" + resolved + "')");
        includeStack_.push_back(resolved);
        DictionaryParser(tokenize(text, resolved), resolved, includeStack_, depth_).parseBody(scopes, true);
        includeStack_.pop_back();
    }

    void parseEntry(std::vector<Dictionary*>& scopes, bool wholeFile) {
        Dictionary& target = *scopes.back();
        const Token key = next();
        skipDimensions(key);
        Dictionary::Entry entry;
        entry.name = key.text;
        entry.file = file_;
        entry.line = key.line;
        if (peek().kind == TokenKind::LBrace) {
            Dictionary child(target.scope_ + "/" + key.text);
            child.file_ = file_;
            child.line_ = next().line;
            enter(child.line_);
            scopes.push_back(&child);
            parseBody(scopes, false);
            scopes.pop_back();
            --depth_;
            if (peek().kind == TokenKind::Semicolon) ++pos_;  // tolerated "};"
            // The OpenFOAM header of a file describes the file, not the case.
            if (wholeFile && key.text == "FoamFile") return;
            entry.value.kind = Value::Kind::Dict;
            entry.value.dict.emplace(std::move(child));
        } else {
            entry.value = parseValue(key, scopes);
            if (peek().kind != TokenKind::Semicolon) {
                const Token& got = peek();
                const int valueLine = tokens_[pos_ - 1].line;
                fail(valueLine, "expected ';' after value of '" + key.text + "', got " + shown(got) +
                                    (got.line != valueLine && got.kind != TokenKind::End ? " on line " + std::to_string(got.line) : ""));
            }
            ++pos_;
        }
        add(target, std::move(entry));
    }

    // OpenFOAM dimension sets "[0 1 -1 0 0 0 0]" after a keyword: accepted, ignored.
    void skipDimensions(const Token& key) {
        if (peek().kind != TokenKind::LBracket) return;
        const int openLine = next().line;
        while (peek().kind == TokenKind::Number) ++pos_;
        if (peek().kind != TokenKind::RBracket)
            fail(openLine, "unbalanced '[': the dimension set of '" + key.text + "' opened here expects numbers and ']', got " + shown(peek()));
        ++pos_;
    }

    Value parseValue(const Token& key, const std::vector<Dictionary*>& scopes) {
        const Token& t = peek();
        switch (t.kind) {
            case TokenKind::Word:
            case TokenKind::Number:
            case TokenKind::String: return scalar(next());
            case TokenKind::Variable: return substitute(next(), scopes);
            case TokenKind::LParen: return parseList(key, scopes);
            default:
                fail(t.line, "expected a value after keyword '" + key.text + "' (a number, word, \"string\", ( list ) or { dictionary }), got " + shown(t));
        }
    }

    Value parseList(const Token& key, const std::vector<Dictionary*>& scopes) {
        const int openLine = next().line;
        enter(openLine);
        Value list;
        list.kind = Value::Kind::List;
        for (;;) {
            const Token& t = peek();
            switch (t.kind) {
                case TokenKind::RParen: ++pos_; --depth_; return list;
                case TokenKind::Word:
                case TokenKind::Number:
                case TokenKind::String: list.items.push_back(scalar(next())); break;
                case TokenKind::Variable: list.items.push_back(substitute(next(), scopes)); break;
                case TokenKind::LParen: list.items.push_back(parseList(key, scopes)); break;
                default:
                    fail(t.line, "unbalanced '(': the list in the value of '" + key.text + "' opened on line " +
                                     std::to_string(openLine) + " is not closed by ')' before " + shown(t));
            }
        }
    }

    static Value scalar(const Token& t) {
        Value v;
        v.kind = t.kind == TokenKind::Number ? Value::Kind::Number
                 : t.kind == TokenKind::String ? Value::Kind::String : Value::Kind::Word;
        v.text = t.text;
        return v;
    }

    // $name: a copy of the value of `name` defined earlier in this or an
    // enclosing dictionary.  Being referenced counts as being used.
    Value substitute(const Token& t, const std::vector<Dictionary*>& scopes) {
        for (auto scope = scopes.rbegin(); scope != scopes.rend(); ++scope) {
            const Dictionary::Entry* e = (*scope)->find(t.text);
            if (!e) continue;
            if (e->value.kind == Value::Kind::Dict)
                fail(t.line, "'$" + t.text + "' refers to a sub-dictionary; only single values and lists can be substituted");
            e->used = true;
            return e->value;
        }
        fail(t.line, "'$" + t.text + "' is not defined: expected a keyword '" + t.text + "' earlier in '" +
                         scopes.back()->scope_ + "' or an enclosing dictionary");
    }

    void add(Dictionary& target, Dictionary::Entry&& entry) {
        const auto [it, inserted] = target.index_.emplace(entry.name, target.entries_.size());
        if (!inserted) {
            const Dictionary::Entry& first = target.entries_[it->second];
            throw InputError(at(entry.file, entry.line) + "duplicate keyword '" + target.scope_ + "/" + entry.name +
                             "'; it is already defined at " + first.file + ":" + std::to_string(first.line));
        }
        target.entries_.push_back(std::move(entry));
    }

    std::vector<Token> tokens_;
    std::size_t pos_ = 0;
    std::string file_;
    std::vector<std::string>& includeStack_;
    int depth_;  // open '{' and '(' around the current token, across #include
};

// ---------------------------------------------------------- construction
Dictionary::Dictionary(std::string scopeName) : scope_(std::move(scopeName)), file_(scope_) {}
Dictionary::Dictionary(const Dictionary&) = default;
Dictionary::Dictionary(Dictionary&&) noexcept = default;
Dictionary& Dictionary::operator=(const Dictionary&) = default;
Dictionary& Dictionary::operator=(Dictionary&&) noexcept = default;
Dictionary::~Dictionary() = default;

Dictionary Dictionary::fromString(const std::string& text, const std::string& sourceName) {
    std::string rootName = std::filesystem::path(sourceName).filename().string();
    Dictionary root(rootName.empty() ? sourceName : rootName);
    root.file_ = sourceName;
    std::vector<std::string> includeStack{sourceName};
    std::vector<Dictionary*> scopes{&root};
    DictionaryParser(tokenize(text, sourceName), sourceName, includeStack).parseBody(scopes, true);
    return root;
}

Dictionary Dictionary::fromFile(const std::string& path) {
    bool ok = false;
    const std::string text = readFile(path, ok);
    if (!ok) throw InputError("cannot open dictionary file '" + path + "' (missing, unreadable or not a regular file)");
    return fromString(text, path);
}

// ------------------------------------------------------------- look-ups
const Dictionary::Entry* Dictionary::find(const std::string& key) const {
    const auto it = index_.find(key);
    return it == index_.end() ? nullptr : &entries_[it->second];
}

const Dictionary::Entry* Dictionary::query(const std::string& key) const {
    if (std::find(accepted_.begin(), accepted_.end(), key) == accepted_.end()) accepted_.push_back(key);
    const Entry* e = find(key);
    if (e) e->used = true;
    return e;
}

const Dictionary::Entry& Dictionary::require(const std::string& key, const std::string& expected) const {
    const Entry* e = query(key);
    if (!e) {
        // A missing keyword is often a misspelt one: point at the unread entry
        // that looks most like it.
        std::vector<std::string> unread;
        for (const auto& entry : entries_)
            if (!entry.used) unread.push_back(entry.name);
        const std::string suggestion = closestWord(key, unread);
        std::string hint;
        if (!suggestion.empty())
            hint = "; found '" + suggestion + "' on line " + std::to_string(find(suggestion)->line) +
                   " instead: did you mean '" + key + "'?";
        throw InputError(at(file_, line_) + "keyword '" + scope_ + "/" + key + "' is missing" +
                         (line_ > 0 ? " from the block opened on this line" : "") + "; expected " + expected + hint);
    }
    return *e;
}

bool Dictionary::has(const std::string& key) const { return query(key) != nullptr; }

bool Dictionary::isDict(const std::string& key) const {
    const Entry* e = query(key);
    return e && e->value.kind == Value::Kind::Dict;
}

const Dictionary& Dictionary::subDict(const std::string& key) const {
    const Entry& e = require(key, "a sub-dictionary '" + key + " { ... }'");
    if (e.value.kind != Value::Kind::Dict)
        throw InputError(at(e.file, e.line) + "keyword '" + scope_ + "/" + key + "': expected a sub-dictionary '" + key +
                         " { ... }', got " + quoteShown(e.value));
    return *e.value.dict;
}

std::vector<std::string> Dictionary::keys() const {
    std::vector<std::string> names;
    names.reserve(entries_.size());
    for (const auto& e : entries_) names.push_back(e.name);
    return names;
}

std::string Dictionary::scopedName() const { return scope_; }
const std::string& Dictionary::fileName() const { return file_; }
int Dictionary::line() const { return line_; }

int Dictionary::lineOf(const std::string& key) const {
    const Entry* e = find(key);
    if (!e) throw InputError(at(file_, line_) + "keyword '" + scope_ + "/" + key + "' is missing");
    return e->line;
}

std::string Dictionary::describe(const std::string& key) const {
    const Entry* e = find(key);
    return "file '" + (e ? e->file : file_) + "', " + (e ? "line " + std::to_string(e->line) + ", " : "") + "keyword '" +
           scope_ + "/" + key + "'";
}

// ---------------------------------------------------------- conversions
namespace {

// Each converter names what it expects (for messages) and converts a value,
// filling `detail` with why a near miss failed (e.g. " (item 2 is 'a')").
template <class T> struct Converter;

bool toDouble(const Value& v, double& out, std::string& detail) {
    if (v.kind != Value::Kind::Number) return false;
    const char* first = v.text.data() + (v.text[0] == '+' ? 1 : 0);  // from_chars rejects '+'
    const auto [end, err] = std::from_chars(first, v.text.data() + v.text.size(), out);
    if (err == std::errc::result_out_of_range || (err == std::errc() && !std::isfinite(out))) {
        detail = " (outside the range of a double)";
        return false;
    }
    return err == std::errc() && end == v.text.data() + v.text.size();
}

template <class Integer> bool toInteger(const Value& v, Integer& out, std::string& detail) {
    if (v.kind != Value::Kind::Number) return false;
    const std::string outOfRange = " (outside the range of a " + std::to_string(std::numeric_limits<Integer>::digits + 1) +
                                   "-bit integer)";
    // Plain digits convert exactly (no detour through double).
    const char* first = v.text.data() + (v.text[0] == '+' ? 1 : 0);
    const char* last = v.text.data() + v.text.size();
    const auto [end, err] = std::from_chars(first, last, out);
    if (end == last) {
        if (err == std::errc::result_out_of_range) detail = outOfRange;
        return err == std::errc();
    }
    // 1e5 is a fine way to write 100000; 2.5 is not an integer.
    double x = 0.0;
    if (!toDouble(v, x, detail) || x != std::floor(x)) return false;
    const double limit = std::ldexp(1.0, std::numeric_limits<Integer>::digits);  // 2^31 or 2^63
    if (x >= limit || x < -limit) {
        detail = outOfRange;
        return false;
    }
    out = static_cast<Integer>(x);
    return true;
}

template <> struct Converter<double> {
    static std::string expected() { return "a number"; }
    static bool from(const Value& v, double& out, std::string& d) { return toDouble(v, out, d); }
};
template <> struct Converter<int> {
    static std::string expected() { return "an integer"; }
    static bool from(const Value& v, int& out, std::string& d) { return toInteger(v, out, d); }
};
template <> struct Converter<long> {
    static std::string expected() { return "an integer"; }
    static bool from(const Value& v, long& out, std::string& d) { return toInteger(v, out, d); }
};
template <> struct Converter<bool> {
    static std::string expected() { return "a switch (true/false, on/off, yes/no)"; }
    static bool from(const Value& v, bool& out, std::string&) {
        if (v.kind != Value::Kind::Word) return false;
        if (v.text == "true" || v.text == "on" || v.text == "yes") { out = true; return true; }
        if (v.text == "false" || v.text == "off" || v.text == "no") { out = false; return true; }
        return false;
    }
};
template <> struct Converter<std::string> {
    static std::string expected() { return "a word or \"string\""; }
    static bool from(const Value& v, std::string& out, std::string&) {
        if (v.kind == Value::Kind::List || v.kind == Value::Kind::Dict) return false;
        out = v.text;
        return true;
    }
};
template <> struct Converter<Vec3> {
    static std::string expected() { return "a vector (x y z) of 3 numbers"; }
    static bool from(const Value& v, Vec3& out, std::string& d) {
        if (v.kind != Value::Kind::List) return false;
        if (v.items.size() != 3) { d = " (" + std::to_string(v.items.size()) + " items)"; return false; }
        for (int k = 0; k < 3; ++k)
            if (!toDouble(v.items[static_cast<std::size_t>(k)], out[k], d)) {
                d = " (item " + std::to_string(k + 1) + " is '" + show(v.items[static_cast<std::size_t>(k)]) + "')" + d;
                return false;
            }
        return true;
    }
};

// "( a b c )" of items that each convert with Converter<Item>.
template <class Item> struct ListConverter {
    static bool from(const Value& v, std::vector<Item>& out, std::string& d) {
        if (v.kind != Value::Kind::List) return false;
        out.resize(v.items.size());
        for (std::size_t k = 0; k < v.items.size(); ++k) {
            std::string itemDetail;
            if (!Converter<Item>::from(v.items[k], out[k], itemDetail)) {
                d = " (item " + std::to_string(k + 1) + " is '" + show(v.items[k]) + "'" + (itemDetail.empty() ? "" : ":" + itemDetail) + ")";
                return false;
            }
        }
        return true;
    }
};
template <> struct Converter<std::vector<double>> : ListConverter<double> {
    static std::string expected() { return "a list of numbers (a b ...)"; }
};
template <> struct Converter<std::vector<int>> : ListConverter<int> {
    static std::string expected() { return "a list of integers (a b ...)"; }
};
template <> struct Converter<std::vector<std::string>> : ListConverter<std::string> {
    static std::string expected() { return "a list of words (a b ...)"; }
};
template <> struct Converter<std::vector<Vec3>> : ListConverter<Vec3> {
    static std::string expected() { return "a list of vectors ((x y z) ...)"; }
};
template <> struct Converter<std::vector<std::vector<double>>> : ListConverter<std::vector<double>> {
    static std::string expected() { return "a list of number lists ((a b ...) ...)"; }
};

}  // namespace

template <class T> T Dictionary::get(const std::string& key) const {
    const Entry& e = require(key, Converter<T>::expected());
    T out{};
    std::string detail;
    if (!Converter<T>::from(e.value, out, detail))
        throw InputError(at(e.file, e.line) + "keyword '" + scope_ + "/" + key + "': expected " + Converter<T>::expected() +
                         ", got " + quoteShown(e.value) + detail);
    return out;
}

template <class T> T Dictionary::getOrDefault(const std::string& key, const T& fallback) const {
    return has(key) ? get<T>(key) : fallback;
}

std::string Dictionary::getOrDefault(const std::string& key, const char* fallback) const {
    return getOrDefault<std::string>(key, std::string(fallback));
}

#define DEM_DICTIONARY_INSTANTIATE(T)                              \
    template T Dictionary::get<T>(const std::string&) const; \
    template T Dictionary::getOrDefault<T>(const std::string&, const T&) const;
DEM_DICTIONARY_INSTANTIATE(double)
DEM_DICTIONARY_INSTANTIATE(int)
DEM_DICTIONARY_INSTANTIATE(long)
DEM_DICTIONARY_INSTANTIATE(bool)
DEM_DICTIONARY_INSTANTIATE(std::string)
DEM_DICTIONARY_INSTANTIATE(Vec3)
DEM_DICTIONARY_INSTANTIATE(std::vector<double>)
DEM_DICTIONARY_INSTANTIATE(std::vector<int>)
DEM_DICTIONARY_INSTANTIATE(std::vector<std::string>)
DEM_DICTIONARY_INSTANTIATE(std::vector<Vec3>)
DEM_DICTIONARY_INSTANTIATE(std::vector<std::vector<double>>)
#undef DEM_DICTIONARY_INSTANTIATE

// ------------------------------------------------------ checked numbers
namespace {
double checkedNumber(const std::string& key, const std::string& expected, const Dictionary::Entry& e,
                     const std::string& scope, bool (*accept)(double, double, double), double lo, double hi) {
    double x = 0.0;
    std::string detail;
    if (!toDouble(e.value, x, detail) || !accept(x, lo, hi))
        throw InputError(at(e.file, e.line) + "keyword '" + scope + "/" + key + "': expected " + expected + ", got " +
                         quoteShown(e.value) + detail);
    return x;
}
}  // namespace

double Dictionary::getPositive(const std::string& key) const {
    const std::string expected = "a positive number (> 0)";
    return checkedNumber(key, expected, require(key, expected), scope_,
                         [](double x, double, double) { return x > 0.0; }, 0.0, 0.0);
}

double Dictionary::getNonNegative(const std::string& key) const {
    const std::string expected = "a non-negative number (>= 0)";
    return checkedNumber(key, expected, require(key, expected), scope_,
                         [](double x, double, double) { return x >= 0.0; }, 0.0, 0.0);
}

double Dictionary::getInRange(const std::string& key, double lo, double hi) const {
    if (!(lo <= hi)) throw std::invalid_argument("Dictionary::getInRange: empty range for '" + key + "'");
    const std::string expected = "a number in [" + formatNumber(lo) + ", " + formatNumber(hi) + "]";
    return checkedNumber(key, expected, require(key, expected), scope_,
                         [](double x, double a, double b) { return a <= x && x <= b; }, lo, hi);
}

std::string Dictionary::getChoice(const std::string& key, const std::vector<std::string>& accepted) const {
    const std::string expected = "one of: " + join(accepted);
    const Entry& e = require(key, expected);
    const Value& v = e.value;
    const bool isWord = v.kind == Value::Kind::Word || v.kind == Value::Kind::String;
    if (isWord && std::find(accepted.begin(), accepted.end(), v.text) != accepted.end()) return v.text;
    std::string message = at(e.file, e.line) + "keyword '" + scope_ + "/" + key + "': ";
    if (!isWord) throw InputError(message + "expected " + expected + ", got " + quoteShown(v));
    const std::string suggestion = closestWord(v.text, accepted);
    throw InputError(message + "unknown value '" + v.text + "'; expected " + expected +
                     (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)"));
}

// -------------------------------------------------------- strictness
void Dictionary::collectUnused(std::vector<std::string>& messages) const {
    for (const auto& e : entries_) {
        if (e.used) {
            if (e.value.kind == Value::Kind::Dict) e.value.dict->collectUnused(messages);
            continue;
        }
        const std::string suggestion = closestWord(e.name, accepted_);
        messages.push_back(at(e.file, e.line) + "unknown keyword '" + e.name + "' in '" + scope_ + "'; " +
                           (suggestion.empty() ? "" : "did you mean '" + suggestion + "'? ") +
                           (accepted_.empty() ? "no keywords are read from '" + scope_ + "'"
                                              : "Accepted: " + join(accepted_)));
    }
}

void Dictionary::checkNoUnusedKeys() const {
    std::vector<std::string> messages;
    collectUnused(messages);
    if (!messages.empty()) throw InputError(join(messages, "\n"));
}

}  // namespace dem
