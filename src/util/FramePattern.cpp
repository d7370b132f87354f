#include "src/util/FramePattern.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>

#include "src/util/Error.h"

namespace vdbdag {
namespace {

// Where the token lies in the file name, and its padding.
struct Token {
    size_t begin = 0, end = 0;  // in the whole path
    int width = 0;              // zero-padded to this many digits (1: none)
};

std::optional<Token> findToken(const std::string& path) {
    const size_t nameStart = path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1;
    for (size_t i = nameStart; i < path.size(); ++i) {
        if (path[i] == '#') {
            size_t j = i;
            while (j < path.size() && path[j] == '#') ++j;
            return Token{i, j, int(j - i)};
        }
        if (path[i] == '%') {  // %d, %4d, %04d
            size_t j = i + 1;
            while (j < path.size() && std::isdigit(static_cast<unsigned char>(path[j]))) ++j;
            if (j < path.size() && path[j] == 'd' && j - i <= 4) {
                const std::string digits = path.substr(i + 1, j - i - 1);
                return Token{i, j + 1, digits.empty() ? 1 : std::max(1, std::stoi(digits))};
            }
        }
        if (path[i] == '$' && i + 1 < path.size() && path[i + 1] == 'F') {  // $F, $F4
            size_t j = i + 2;
            while (j < path.size() && j < i + 4 && std::isdigit(static_cast<unsigned char>(path[j]))) ++j;
            const std::string digits = path.substr(i + 2, j - i - 2);
            return Token{i, j, digits.empty() ? 1 : std::max(1, std::stoi(digits))};
        }
    }
    return std::nullopt;
}

std::string padded(int64_t number, int width) {
    const uint64_t magnitude = number < 0 ? uint64_t(0) - uint64_t(number) : uint64_t(number);
    std::string digits = std::to_string(magnitude);
    if (int(digits.size()) < width) digits.insert(0, size_t(width) - digits.size(), '0');
    return number < 0 ? "-" + digits : digits;
}

} // namespace

bool isFramePattern(const std::string& text) { return findToken(text).has_value(); }

std::string framePath(const std::string& pattern, int64_t number) {
    const auto token = findToken(pattern);
    if (!token) throw Error(pattern + ": has no frame token (####, %04d or $F4)");
    return pattern.substr(0, token->begin) + padded(number, token->width) + pattern.substr(token->end);
}

std::vector<FrameFile> expandFramePattern(const std::string& pattern) {
    const auto token = findToken(pattern);
    if (!token) throw Error(pattern + ": has no frame token (####, %04d or $F4)");
    const std::filesystem::path whole(pattern);
    const std::filesystem::path folder = whole.parent_path().empty() ? std::filesystem::path(".") : whole.parent_path();
    const size_t nameStart = pattern.size() - whole.filename().string().size();
    const std::string prefix = pattern.substr(nameStart, token->begin - nameStart), suffix = pattern.substr(token->end);
    std::vector<FrameFile> frames;
    std::error_code ec;
    std::filesystem::directory_iterator it(folder, ec), endIt;
    if (ec) throw Error(pattern + ": cannot list its folder " + folder.string() + " (" + ec.message() + ")");
    for (; it != endIt; it.increment(ec)) {
        if (ec) throw Error(pattern + ": cannot list its folder " + folder.string() + " (" + ec.message() + ")");
        const std::string name = it->path().filename().string();
        if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) || !name.ends_with(suffix)) continue;
        const std::string middle = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
        const size_t digitsFrom = middle[0] == '-' ? 1 : 0;
        if (middle.size() == digitsFrom || middle.size() - digitsFrom > 18 ||
            !std::all_of(middle.begin() + long(digitsFrom), middle.end(), [](unsigned char c) { return std::isdigit(c); }))
            continue;
        const int64_t number = std::stoll(middle);
        const std::string path = pattern.substr(0, nameStart) + name;
        if (framePath(pattern, number) != path) continue;  // another padding: not this pattern's
        frames.push_back({number, path});
    }
    std::sort(frames.begin(), frames.end(), [](const FrameFile& a, const FrameFile& b) { return a.number < b.number; });
    return frames;
}

std::string withoutFrameToken(const std::string& pattern) {
    const auto token = findToken(pattern);
    if (!token) return pattern;
    size_t begin = token->begin;
    const size_t nameStart = pattern.find_last_of('/') == std::string::npos ? 0 : pattern.find_last_of('/') + 1;
    if (begin > nameStart && (pattern[begin - 1] == '.' || pattern[begin - 1] == '_' || pattern[begin - 1] == '-')) --begin;
    size_t end = token->end;
    if (begin == token->begin && end < pattern.size() && (pattern[end] == '_' || pattern[end] == '-')) ++end;  // "####_smoke.vdb"
    return pattern.substr(0, begin) + pattern.substr(end);
}

std::optional<int64_t> frameNumberOf(const std::string& path) {
    const std::string name = std::filesystem::path(path).filename().string();
    // The last digit run, which must end the name or meet its extensions
    // (smoke.0042.vdb, smoke_12.nii.gz; not ct_v2_scan.nii.gz).
    size_t end = name.size();
    while (end > 0 && !std::isdigit(static_cast<unsigned char>(name[end - 1]))) --end;
    if (end == 0 || (end != name.size() && name[end] != '.')) return std::nullopt;
    size_t begin = end;
    while (begin > 0 && std::isdigit(static_cast<unsigned char>(name[begin - 1]))) --begin;
    if (end - begin > 18) return std::nullopt;
    return std::stoll(name.substr(begin, end - begin));
}

std::vector<FrameFile> framesOfList(const std::vector<std::string>& paths) {
    std::vector<FrameFile> frames;
    std::set<int64_t> seen;
    bool named = true;
    for (const std::string& p : paths) {
        const auto n = frameNumberOf(p);
        if (!n || !seen.insert(*n).second) named = false;
        frames.push_back({n.value_or(0), p});
    }
    if (named) {
        std::stable_sort(frames.begin(), frames.end(), [](const FrameFile& a, const FrameFile& b) { return a.number < b.number; });
    } else {
        for (size_t i = 0; i < frames.size(); ++i) frames[i].number = int64_t(i) + 1;
    }
    return frames;
}

bool FrameSelection::contains(int64_t frame) const {
    return std::any_of(ranges.begin(), ranges.end(), [&](const auto& r) { return frame >= r.first && frame <= r.second; });
}

FrameSelection parseFrameSelection(const std::string& text) {
    FrameSelection selection;
    auto fail = [&] { throw Error("--frames " + text + ": not a frame selection (e.g. 12, 10-20 or 1,5,9-12)"); };
    size_t at = 0;
    auto number = [&]() -> int64_t {
        const size_t from = at;
        if (at < text.size() && text[at] == '-') ++at;
        while (at < text.size() && std::isdigit(static_cast<unsigned char>(text[at]))) ++at;
        if (at == from || (text[from] == '-' && at == from + 1) || at - from > 18) fail();
        return std::stoll(text.substr(from, at - from));
    };
    while (true) {
        const int64_t low = number();
        int64_t high = low;
        if (at < text.size() && text[at] == '-') {
            ++at;
            high = number();
        }
        if (high < low) fail();
        selection.ranges.push_back({low, high});
        if (at == text.size()) break;
        if (text[at] != ',') fail();
        ++at;
    }
    return selection;
}

} // namespace vdbdag
