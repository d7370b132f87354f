// Private text helpers shared by the NRRD and MetaImage header parsers:
// trimming, case folding, strict number parsing (the whole token must be a
// finite number, so "1.5mm" or "nan" is an error, not 1.5 or NaN).
#pragma once
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <istream>
#include <string>
#include <vector>

#include "src/util/Error.h"

namespace vdbdag::bridge::detail {

inline std::string trim(const std::string& s) {
    size_t b = 0, e = s.size();
    while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
    while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
    return s.substr(b, e - b);
}

inline std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// Whitespace-separated tokens.
inline std::vector<std::string> tokens(const std::string& s) {
    std::vector<std::string> out;
    size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
        size_t j = i;
        while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j]))) ++j;
        if (j > i) out.push_back(s.substr(i, j - i));
        i = j;
    }
    return out;
}

inline double parseNumber(const std::string& token, const std::string& what) {
    const char* begin = token.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(begin, &end);
    if (token.empty() || end != begin + token.size() || !std::isfinite(v) || errno == ERANGE)
        throw Error(what + ": '" + token + "' is not a finite number");
    return v;
}

inline int64_t parseInteger(const std::string& token, const std::string& what) {
    const char* begin = token.c_str();
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(begin, &end, 10);
    if (token.empty() || end != begin + token.size() || errno == ERANGE) throw Error(what + ": '" + token + "' is not an integer");
    return int64_t(v);
}

// std::getline with a budget: reads at most `budget` bytes (counting the
// newline) and throws `tooLong` past it, so a header "line" of gigabytes is
// never held in memory. Returns false at the end of the stream.
inline bool getBoundedLine(std::istream& in, std::string& line, size_t& budget, const std::string& tooLong) {
    line.clear();
    std::streambuf* buffer = in.rdbuf();
    bool any = false;
    for (;;) {
        const int c = buffer->sbumpc();
        if (c == std::char_traits<char>::eof()) {
            if (!any) in.setstate(std::ios::eofbit | std::ios::failbit);
            else in.setstate(std::ios::eofbit);
            return any;
        }
        any = true;
        if (budget == 0) throw Error(tooLong);
        --budget;
        if (c == '\n') return true;
        line.push_back(char(c));
    }
}

inline std::vector<double> parseNumbers(const std::string& s, size_t count, const std::string& what) {
    const std::vector<std::string> t = tokens(s);
    if (t.size() != count) throw Error(what + ": expected " + std::to_string(count) + " numbers, found " + std::to_string(t.size()));
    std::vector<double> out;
    for (const auto& x : t) out.push_back(parseNumber(x, what));
    return out;
}

} // namespace vdbdag::bridge::detail
