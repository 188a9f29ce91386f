// SPDX-License-Identifier: MIT
// The `binocle` command line as one CLI11 app: registry, global options, shared helpers.
#include "cli/command.hpp"

#include <binocle/abi.h>
#include <binocle/numbers.hpp>
#include <binocle/text.hpp>

#include <climits>
#include <cmath>
#include <functional>
#include <filesystem>

namespace binocle::cli {

namespace {

std::map<std::string, Command> &registry() {
    static std::map<std::string, Command> r;
    return r;
}

// CLI11's help, with the lower-case "usage:" of the rest of the project's messages.
class Formatter : public CLI::Formatter {
public:
    std::string make_usage(const CLI::App *app, std::string name) const override {
        std::string u = CLI::Formatter::make_usage(app, std::move(name));
        if (u.rfind("Usage:", 0) == 0) u[0] = 'u';
        return u;
    }
};

} // namespace

const std::map<std::string, Command> &commands() { return registry(); }

Register::Register(Command c) { registry()[c.name] = std::move(c); }

std::unique_ptr<CLI::App> makeApp(std::map<const CLI::App *, Runner> &runners) {
    auto app = std::make_unique<CLI::App>("binocle: stereo camera design and processing framework", "binocle");
    app->formatter(std::make_shared<Formatter>());
    app->set_version_flag("--version", std::string("binocle ") + BINOCLE_VERSION + " (plugin ABI " +
                                           std::to_string(BINOCLE_ABI_VERSION) + ", API " +
                                           std::to_string(BINOCLE_API_VERSION) + ")");
    // Global options are defined in main (they need its state); here what the subcommands
    // inherit: unknown arguments are collected (main names them, with a suggestion) and
    // options of the top level are accepted after the command too.
    app->allow_extras();
    app->fallthrough();
    app->require_subcommand(0, 1);
    const std::string common =
        "Exit status: 0 ok, 1 the run failed, 2 wrong usage (unknown option, bad value).\n"
        "Global options, before or after the command: --log-level LEVEL (trace, debug, info, warn,\n"
        "error, off; default info or $BINOCLE_LOG_LEVEL), --log-file FILE, --version.\n";
    app->footer(common + "Run `binocle <command> --help` for a command's options.\n"
                         "Plugins are searched in $BINOCLE_PLUGIN_PATH, the install prefix and the build tree.\n");
    for (const auto &[name, c] : commands()) {
        CLI::App *sub = app->add_subcommand(name, c.summary);
        sub->footer((c.details.empty() ? "" : c.details + "\n\n") + common);
        runners[sub] = c.define(*sub);
    }
    return app;
}

void addRigArgs(CLI::App &app, RigArgs &args, bool required) {
    auto *rig = app.add_option("rig", args.file, "the rig file (YAML)")->type_name("RIG.yaml");
    if (required) rig->required();
    app.add_option("--set", args.overrides, "override a value of the rig, e.g. --set matcher.num_disparities=128 (repeatable)")
        ->type_name("KEY=VALUE")
        ->allow_extra_args(false);
}

CLI::Option *addFramesOption(CLI::App &app, int64_t &frames, const std::string &help) {
    return app.add_option("--frames", frames, help)->type_name("N")->check(atLeast(1));
}

RigConfig loadRig(const RigArgs &args, const PluginHost &host) {
    try {
        std::vector<Override> overrides;
        for (const auto &s : args.overrides) overrides.push_back(Override::parse(s));
        return loadRig(args.file, overrides, host);
    } catch (const OverrideError &e) {
        throw UsageError(e.what()); // a bad --set is a bad value on the command line: exit 2
    }
}

namespace {

// A whole number by the one number reader (binocle/numbers.hpp), within [min, max]. The
// text CLI11 then converts is plain decimal, so its own base detection ("010" -> 8,
// "0x10" -> 16) never sees a prefix or a leading zero.
CLI::Validator wholeNumberValidator(long long min, long long max, std::string expected) {
    return CLI::Validator(
        [min, max, expected](std::string &text) -> std::string {
            int64_t v = 0;
            std::string why;
            if (!sdk::parseDecimalInteger(text, v, &why) || v < min || v > max)
                return "'" + sdk::printable(text) + "': expected " + expected + sdk::numberWhyDetail(why);
            return "";
        },
        "");
}

// A real number by the one number reader: decimal, finite, no hexadecimal float.
CLI::Validator numberValidator(std::function<bool(double)> fits, std::string expected) {
    return CLI::Validator(
        [fits = std::move(fits), expected](std::string &text) -> std::string {
            double v = 0;
            std::string why;
            if (!sdk::parseDecimalReal(text, v, &why) || !fits(v))
                return "'" + sdk::printable(text) + "': expected " + expected + sdk::numberWhyDetail(why);
            return "";
        },
        "");
}

} // namespace

CLI::Validator atLeast(long long min) {
    return wholeNumberValidator(min, LLONG_MAX, "a whole number >= " + std::to_string(min));
}

CLI::Validator wholeNumber() { return wholeNumberValidator(LLONG_MIN, LLONG_MAX, "a whole number"); }

CLI::Validator wholeNumberIn(long long min, long long max) {
    return wholeNumberValidator(min, max, "a whole number " + std::to_string(min) + ".." + std::to_string(max));
}

CLI::Validator positiveNumber() {
    return numberValidator([](double v) { return v > 0; }, "a number > 0");
}

CLI::Validator decimalNumber() {
    return numberValidator([](double) { return true; }, "a decimal number");
}

CLI::Validator wholeNumbers(char separator, long long min) {
    return CLI::Validator(
        [separator, min](std::string &text) -> std::string {
            const std::string expected = "whole numbers >= " + std::to_string(min) + " separated by '" + separator + "'";
            size_t start = 0;
            while (start <= text.size()) {
                size_t end = text.find(separator, start);
                if (end == std::string::npos) end = text.size();
                int64_t v = 0;
                std::string why;
                if (!sdk::parseDecimalInteger(std::string_view(text).substr(start, end - start), v, &why) || v < min)
                    return "'" + sdk::printable(text) + "': expected " + expected + sdk::numberWhyDetail(why);
                start = end + 1;
            }
            return "";
        },
        "");
}

} // namespace binocle::cli
