#include "cli/command_line.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>

namespace rthdist::cli {

namespace {

// Ends the arguments: an option whose values run past the end reads it
// instead of an argument. No argument is two NULs (no argument has one).
const std::string kEnd(2, '\0');

// "--name=value" -> "--name=\0value": CLI11 splits "--name=" and "--name"
// alike (and takes the next argument for the latter), the NUL tells them
// apart. Tokens that do not start with "--" are left as they are.
std::string markInline(const std::string& token) {
    const size_t eq = token.find('=');
    if (token.size() <= 2 || token.compare(0, 2, "--") != 0 || eq == std::string::npos) return token;
    std::string marked = token;
    marked.insert(eq + 1, 1, '\0');
    return marked;
}

std::string unmark(std::string token) {
    token.erase(std::remove(token.begin(), token.end(), '\0'), token.end());
    return token;
}

bool isInline(const std::string& value) { return value != kEnd && !value.empty() && value[0] == '\0'; }

}  // namespace

CommandLine::CommandLine(OtherHandler other)
    : m_app(std::make_unique<CLI::App>()), m_other(std::move(other)) {
    m_app->set_help_flag();  // --help and -h are the tools' own
    m_app->allow_extras();   // operands and unknown options go to m_other
}

CommandLine::~CommandLine() = default;

CommandLine& CommandLine::flag(const std::string& name, FlagHandler handler) {
    option(name, 0, [handler = std::move(handler)](const std::vector<std::string>&, bool inlineValue) {
        handler(inlineValue);
    });
    return *this;
}

CommandLine& CommandLine::option(const std::string& name, int count, OptionHandler handler) {
    m_maxCount = std::max(m_maxCount, count);
    const CLI::callback_t onParse = [this, handler = std::move(handler)](const CLI::results_t& results) {
        std::vector<std::string> values;
        for (const std::string& r : results) {
            if (r == kEnd) break;
            values.push_back(unmark(r));
        }
        try {
            handler(values, !results.empty() && isInline(results.front()));
        } catch (const UsageError&) {
            runOthers();  // an unknown option before this one is the first error
            throw;
        }
        return true;
    };
    CLI::Option* opt = m_app->add_option(name, onParse);
    if (count == 0) {
        opt->expected(0);  // a flag: its result is "--flag=value"'s marked value, if any
    } else {
        // count values per occurrence, each taken whatever it looks like.
        opt->type_size(count)->expected(1);
    }
    opt->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)->trigger_on_parse();
    return *this;
}

void CommandLine::runOthers() {
    const std::vector<std::string> others = m_app->remaining();
    for (; m_othersRun < others.size(); ++m_othersRun) {
        const std::string& token = others[m_othersRun];
        if (token == kEnd) continue;
        const bool endMark = !m_afterEnd && token == "--";
        m_other(unmark(token), m_afterEnd);
        m_afterEnd = m_afterEnd || endMark;
    }
}

std::optional<std::string> CommandLine::parse(std::span<const std::string> args) {
    // CLI11 reads the vector from its back: the first argument last, after it
    // as many end marks as the longest option could read past the end.
    std::vector<std::string> reversed(static_cast<size_t>(std::max(m_maxCount, 1)), kEnd);
    for (auto it = args.rbegin(); it != args.rend(); ++it) reversed.push_back(markInline(*it));
    try {
        m_app->parse(std::move(reversed));
        runOthers();
    } catch (const UsageError& e) {
        return e.message;
    } catch (const CLI::Error& e) {  // not reached: CLI11 only splits, the handlers judge
        return std::string("cannot parse the command line: ") + e.what();
    }
    return std::nullopt;
}

}  // namespace rthdist::cli
