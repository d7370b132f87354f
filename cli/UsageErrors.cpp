// See UsageErrors.h.
#include "cli/UsageErrors.h"

#include <algorithm>
#include <cstdio>

namespace vdbdag::cli {
namespace {

size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

std::vector<std::string> commandNames(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(sub->get_name());
    return names;
}

// The subcommand named on the command line, if any (the first word that is one).
CLI::App* chosenCommand(CLI::App& app, int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string word = argv[i];
        if (word.empty() || word[0] == '-') continue;
        for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
            if (sub->get_name() == word) return sub;
        return nullptr;  // the first plain word names the command, or nothing does
    }
    return nullptr;
}

std::vector<std::string> optionNames(const CLI::App& command) {
    std::vector<std::string> names;
    for (const CLI::Option* o : command.get_options()) {
        for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
        for (const std::string& s : o->get_snames()) names.push_back("-" + s);
    }
    return names;
}

// CLI11's "The following arguments were not expected: A B" as its words.
std::vector<std::string> unexpectedWords(const std::string& message) {
    std::vector<std::string> words;
    const size_t colon = message.find(": ");
    if (colon == std::string::npos) return words;
    std::string word;
    for (const char c : message.substr(colon + 2)) {
        if (c == ' ') {
            if (!word.empty()) words.push_back(word);
            word.clear();
        } else {
            word += c;
        }
    }
    if (!word.empty()) words.push_back(word);
    return words;
}

int usageLine(const std::string& who, const std::string& what) {
    std::fprintf(stderr, "%s: %s (see %s --help)\n", who.c_str(), what.c_str(), who.c_str());
    return kUsageExitCode;
}

} // namespace

std::string closestName(const std::string& word, const std::vector<std::string>& names) {
    std::string best, onlyPrefixed;
    size_t bestDistance = std::max<size_t>(2, word.size() / 3) + 1, prefixed = 0;
    for (const std::string& name : names) {
        const size_t d = editDistance(word, name);
        if (d < bestDistance) bestDistance = d, best = name;
        if (word.size() >= 2 && name.rfind(word, 0) == 0) ++prefixed, onlyPrefixed = name;
    }
    if (!best.empty()) return best;
    return prefixed == 1 ? onlyPrefixed : std::string();
}

std::optional<int> answerHelpCommand(CLI::App& app, int argc, char** argv) {
    if (argc < 2 || std::string(argv[1]) != "help") return std::nullopt;
    if (argc == 2) {
        std::fputs(app.help().c_str(), stdout);
        return 0;
    }
    const std::string name = argv[2];
    for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        if (sub->get_name() == name) {
            // Exactly what `vdbdag NAME --help` prints (CLI11 takes the words last first).
            std::vector<std::string> words{"--help", name};
            try {
                app.parse(words);
            } catch (const CLI::ParseError& e) {
                return app.exit(e);
            }
            return 0;
        }
    const std::string guess = closestName(name, commandNames(app));
    return usageLine("vdbdag", "'" + name + "' is not a command" + (guess.empty() ? "" : "; did you mean '" + guess + "'?"));
}

int answerParseError(CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    CLI::App* command = chosenCommand(app, argc, argv);
    const std::string who = command ? "vdbdag " + command->get_name() : "vdbdag";
    const std::string message = e.what();
    if (!command) {
        // No command: the first plain word is a mistyped one, or there is none.
        for (int i = 1; i < argc; ++i) {
            const std::string word = argv[i];
            if (word.empty() || word[0] == '-') continue;
            const std::string guess = closestName(word, commandNames(app));
            return usageLine(who, "'" + word + "' is not a command" + (guess.empty() ? "" : "; did you mean '" + guess + "'?"));
        }
        if (dynamic_cast<const CLI::RequiredError*>(&e)) return usageLine(who, "a command is required");
    }
    if (dynamic_cast<const CLI::ExtrasError*>(&e)) {  // (its name is the command's, not "ExtrasError")
        const std::vector<std::string> words = unexpectedWords(message);
        const auto option = std::find_if(words.begin(), words.end(), [](const std::string& w) { return w.size() > 1 && w[0] == '-'; });
        if (option != words.end()) {
            const std::string name = option->substr(0, option->find('='));
            const std::string guess = closestName(name, optionNames(command ? *command : app));
            return usageLine(who, "unknown option '" + name + "'" + (guess.empty() ? "" : "; did you mean '" + guess + "'?"));
        }
        if (!words.empty()) return usageLine(who, "unexpected argument '" + words.front() + "'");
    }
    // A word outside an option's set (CLI11: "--view: fornt not in {iso,front,back,side,top}"): the closest member.
    if (const size_t colon = message.find(": "), notIn = message.rfind(" not in {");
        colon != std::string::npos && notIn != std::string::npos && notIn > colon && message.back() == '}') {
        const std::string option = message.substr(0, colon), value = message.substr(colon + 2, notIn - colon - 2);
        std::vector<std::string> members;
        std::string list = message.substr(notIn + 9, message.size() - notIn - 10);
        for (size_t at = 0; at <= list.size();) {
            const size_t comma = std::min(list.find(',', at), list.size());
            members.push_back(list.substr(at, comma - at));
            at = comma + 1;
        }
        std::string listed;
        for (const std::string& m : members) listed += (listed.empty() ? "" : ", ") + m;
        const std::string guess = closestName(value, members);
        return usageLine(who, option + ": '" + value + "' is not one of " + listed + (guess.empty() ? "" : "; did you mean '" + guess + "'?"));
    }
    return usageLine(who, message);
}

} // namespace vdbdag::cli
