// Command lines of the rthdist tools, tokenized by CLI11 and judged by each
// tool's own rules, so that every tool keeps the flags, messages and
// first-error-wins order it has always had (README "Usage"):
//
// - options are long ("--name"); a value follows as the next argument (taken
//   whatever it looks like: "--bits -1" gives "-1") or inline ("--name=value",
//   the handler is told which; "--name=" is an empty inline value);
// - an option's handler runs as soon as its values are read, and may throw
//   UsageError; errors come back in command-line order: a rejected value
//   after an unknown option reports the unknown option;
// - everything CLI11 does not take as a known option or its value (operands,
//   unknown or short options, "-h", the "--" that ends the options) goes to the
//   tool's `other` handler in command-line order.
//
// Arguments cannot contain NUL bytes (argv never does): parse() uses NUL to
// mark inline values and the end of the arguments.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace rthdist::cli {

// Thrown by a handler to reject the command line with `message`.
struct UsageError {
    std::string message;
};

class CommandLine {
public:
    // withValue: given as "--flag=value".
    using FlagHandler = std::function<void(bool withValue)>;
    // values: what followed the option, fewer than its count when the command
    // line ended first; inlineValue: the first came as "--name=value".
    using OptionHandler = std::function<void(const std::vector<std::string>& values, bool inlineValue)>;
    // afterEnd: the token came after the "--" that ends the options (the
    // "--" itself comes with afterEnd false).
    using OtherHandler = std::function<void(const std::string& token, bool afterEnd)>;

    explicit CommandLine(OtherHandler other);
    ~CommandLine();
    CommandLine(const CommandLine&) = delete;
    CommandLine& operator=(const CommandLine&) = delete;

    CommandLine& flag(const std::string& name, FlagHandler handler);
    // An option followed by `count` values (1 or more).
    CommandLine& option(const std::string& name, int count, OptionHandler handler);

    // Parses argv[1..]: the message of the first error in command-line
    // order, or nullopt when every handler accepted its part.
    [[nodiscard]] std::optional<std::string> parse(std::span<const std::string> args);

private:
    void runOthers();  // the tokens CLI11 has set aside so far, each once

    std::unique_ptr<CLI::App> m_app;
    OtherHandler m_other;
    int m_maxCount = 0;
    size_t m_othersRun = 0;
    bool m_afterEnd = false;
};

}  // namespace rthdist::cli
