// SPDX-License-Identifier: MIT
// The `binocle` command: one file per subcommand (cmd_<name>.cpp) registers itself with
// its options defined on a CLI11 app and the function that runs once they are parsed.
#pragma once

#include "app/request.hpp"
#include "config/rig_config.hpp"
#include "core/error.hpp"

#include <CLI/CLI.hpp>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace binocle::cli {

// Exit statuses of every command (README "Exit statuses").
enum ExitStatus { kExitOk = 0, kExitFailed = 1, kExitUsage = 2 };

// A mistake on the command line that CLI11 cannot see (options that exclude each other,
// a malformed list): the command stops with exit status 2, like a parse error. The
// application layer's refusal of a bad request is the same error.
using UsageError = app::RequestError;

// What runs once the command line is parsed; returns the exit status. Exceptions:
// UsageError -> 2, any other -> 1, with the message logged as an error.
using Runner = std::function<int()>;

struct Command {
    std::string name;
    std::string summary;  // one line, for `binocle --help` (and the top of `binocle <name> --help`)
    std::string details;  // shown after the options in `binocle <name> --help`
    // Defines the command's positionals and options on `app` (bind them to a struct the
    // returned Runner shares, e.g. a std::shared_ptr) and returns the Runner.
    std::function<Runner(CLI::App &app)> define;
};

// The `define` of a command whose work is a plain function of a plain options struct:
// `options(app, args)` binds the positionals and options to a fresh `Args` (shared with
// the Runner), and the Runner calls `run(args)`, or `run(args, app)` for a command that
// asks the parsed app itself (which options were given, its parent).
template <class Args, class Options, class Run>
std::function<Runner(CLI::App &app)> define(Options options, Run run) {
    return [options, run](CLI::App &app) -> Runner {
        auto args = std::make_shared<Args>();
        options(app, *args);
        if constexpr (std::is_invocable_v<Run, Args &, CLI::App &>)
            return [args, run, &app] { return run(*args, app); };
        else
            return [args, run] { return run(*args); };
    };
}

// One static object per command file:
// `Register nameCommand{{"name", "summary", "details", define<NameArgs>(options, run)}};`
struct Register {
    explicit Register(Command c);
};

const std::map<std::string, Command> &commands();

// The whole command line: global options (--log-level, --log-file, --version) and every
// registered command as a subcommand. `runners` receives each subcommand's Runner.
std::unique_ptr<CLI::App> makeApp(std::map<const CLI::App *, Runner> &runners);

// The rig file and its --set overrides, for the commands that load a rig.
struct RigArgs {
    std::string file;
    std::vector<std::string> overrides;
};
// RIG (positional; required unless `required` is false) and --set KEY=VALUE (repeatable).
void addRigArgs(CLI::App &app, RigArgs &args, bool required = true);
// The rig with every --set override applied, validated against the plugins `host` found.
RigConfig loadRig(const RigArgs &args, const PluginHost &host);

// The `define` of a command on a rig: RIG and --set into `args.rig` first, then `options`.
template <class Args, class Options, class Run>
std::function<Runner(CLI::App &app)> defineOnRig(Options options, Run run) {
    return define<Args>(
        [options](CLI::App &app, Args &args) {
            addRigArgs(app, args.rig);
            options(app, args);
        },
        run);
}

// --frames N: stop after N frames, a whole number >= 1 (`help` says of what and the default).
CLI::Option *addFramesOption(CLI::App &app, int64_t &frames, const std::string &help);
// Validators with messages in the words of the other errors. Every numeric option takes
// one of these, before any other check: they read the text with the one number reader
// (binocle/numbers.hpp: decimal only), so that `--frames 010` is an error, as in a rig
// file, and not 8 (CLI11 alone detects a base: "010" -> 8, "0x10" -> 16).
CLI::Validator atLeast(long long min);   // a whole number >= min
CLI::Validator wholeNumber();            // any whole number (then e.g. CLI::Range)
CLI::Validator wholeNumberIn(long long min, long long max); // a whole number min..max
CLI::Validator positiveNumber();         // a finite real > 0
CLI::Validator decimalNumber();          // any finite real (then e.g. CLI::Range)
// Whole numbers >= min joined by `separator`, e.g. "2/8" for --shard.
CLI::Validator wholeNumbers(char separator, long long min);

// A numeric option: NAME VALUE into `value`, `type` naming the value in the help, read by
// `number` (one of the validators above) before any other check the caller adds.
template <class T>
CLI::Option *addNumber(CLI::App &app, const std::string &name, T &value, const std::string &help,
                       const std::string &type, const CLI::Validator &number) {
    return app.add_option(name, value, help)->type_name(type)->check(number);
}

} // namespace binocle::cli
